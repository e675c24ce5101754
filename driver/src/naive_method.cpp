#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {

std::unique_ptr<RenderMethod> make_naive_method() {
  throw InputError("command line", "--method", "method 'naive' is not available in this build");
}

}  // namespace facet::driver::detail
