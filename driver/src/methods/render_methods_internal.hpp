#pragma once
// Factories of the render methods, one per implementation file; make_render_method
// (render_method.cpp) picks one by name.
#include <memory>
#include <span>
#include <string_view>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/glc.hpp"

namespace facet::driver::detail {

std::unique_ptr<RenderMethod> make_facet_pipeline();        // "facets" (facet_pipeline.cpp)
std::unique_ptr<RenderMethod> make_facet_gs_pipeline();     // "facets-gs" (facet_gs_pipeline.cpp)
std::unique_ptr<RenderMethod> make_tessellated_pipeline();  // "tessellated"
std::unique_ptr<RenderMethod> make_naive_method();          // "naive" (naive_method.cpp)
std::unique_ptr<RenderMethod> make_cubemap_method();        // "cubemap" (cubemap_method.cpp)
std::unique_ptr<RenderMethod> make_perspective_method();    // "perspective"
std::unique_ptr<RenderMethod> make_vertex_method();         // "vertex" (vertex_method.cpp)
std::unique_ptr<RenderMethod> make_glc_method();            // "glc" (glc_method.cpp)
std::unique_ptr<RenderMethod> make_glc_2pass_method();      // "glc-2pass" (glc_2pass_method.cpp)

// For every method but glc and glc-2pass, in its prepare: throws InputError(OptionName "method")
// when an output is a GLC camera's, whose warp only carries the output size.
void refuse_glc_outputs(std::span<const OutputSpec> outputs, std::string_view method);

// The GLC camera's piece of every pixel (PiecewiseGlc::piece_of_pixel) as an R32I texture in GL
// rows (row 0 at the bottom), nearest filtering; glc_method.cpp.
Texture upload_piece_map(const PiecewiseGlc& camera);

}  // namespace facet::driver::detail
