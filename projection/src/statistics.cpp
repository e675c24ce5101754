#include "facet/projection/statistics.hpp"

#include <algorithm>

namespace facet {

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const std::size_t n = values.size(), upper = n / 2;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(upper), values.end());
  if (n % 2) return values[upper];
  const double below = *std::max_element(values.begin(), values.begin() + std::ptrdiff_t(upper));
  return 0.5 * (below + values[upper]);
}

}  // namespace facet
