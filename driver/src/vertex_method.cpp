// The per-vertex nonlinear projection baseline ("vertex"): not built yet.
#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {

std::unique_ptr<RenderMethod> make_vertex_method() {
  throw InputError("command line", "--method", "method 'vertex' is not available in this build");
}

}  // namespace facet::driver::detail
