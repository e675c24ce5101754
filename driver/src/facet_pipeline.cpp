#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {

std::unique_ptr<RenderMethod> make_facet_pipeline() {
  throw InputError("command line", "--method", "method 'facets' is not available in this build");
}

}  // namespace facet::driver::detail
