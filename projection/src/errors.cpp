#include "facet/projection/errors.hpp"

#include <cstdio>
#include <cstdlib>

namespace facet {

void assertion_failed(const char* function, const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s: assertion '%s' failed (%s:%d)\n", function, condition, file, line);
  std::abort();
}

}  // namespace facet
