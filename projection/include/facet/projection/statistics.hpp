// Order statistics of timings and errors, shared by the bench, the CLI and the tests.
#pragma once

#include <vector>

namespace facet {

// The median of `values`: the middle one, or the mean of the two middle ones for an even count;
// 0 for none.
double median(std::vector<double> values);

}  // namespace facet
