#pragma once
// Materials: the fragment shading of every render method, chosen per run (`--material`) or per
// scene material (Material::shader; MaterialPrograms links one program per distinct shader). A
// material is GLSL that defines `vec4 shade(MaterialInput m)`, compiled against the interface in
// shaders/scene/material_interface.frag (world position, normal, uv, barycentric coordinates and
// edge distances in output pixels, distance from the eye, depth, pixel position, triangle ID,
// base colour and texture). shaders/scene/material.frag gathers the inputs, calls shade() and
// writes the colour and the triangle ID itself, so the IDs, the depth and the replication never
// depend on the material. Built-ins live under shaders/scene/materials/.
#include <span>
#include <string>
#include <string_view>

#include "facet/driver/program.hpp"
#include "facet/driver/scene.hpp"  // MaterialShader

namespace facet::driver {

// "lit" (the default), "solid-wireframe", "pen-and-ink", "procedural".
std::span<const std::string_view> builtin_material_names();

// A built-in by name, else the GLSL file `name_or_file` (a path ending in .frag), read whole.
// InputError (field `--material`) for an unknown name, a file that is missing, not a regular
// file, over 1 MiB, or whose text uses `discard` or writes gl_FragDepth (either would let the
// material change the triangle IDs or the depth).
MaterialShader load_material_shader(std::string_view name_or_file);

// The text compiled as the material's fragment shader object: the interface, `#line 1`, then
// the material's own text (so that line numbers are the material file's).
std::string material_stage_text(std::string_view material_text);

// Adds the fragment stage of a material program, three shader objects compiled with the
// interface in front: `gather`, which defines main(), gathers MaterialInput, calls shade() and
// writes colour and triangle ID (scene/material.frag, the rasterizing methods'; glc/glc_hit.frag,
// the GLC ray cast's), scene/sun_and_sky.frag and the material.
void add_material_stages(ProgramBuilder& builder, const MaterialShader& material,
                         std::string_view gather = "scene/material.frag");

// Links a program whose fragment stage add_material_stages made. The material's compile error,
// or a link error when the material does not link alone either (it defines no shade(), say),
// becomes an InputError (field `--material`) naming that file, the line and the driver's first
// error line; other errors stay ShaderErrors with the whole log. Needs a current context.
Program link_with_material(const ProgramBuilder& builder, const MaterialShader& material);

// Compiles and links the material with scene/material.frag and a minimal vertex stage:
// link_with_material's InputError before any scene work. Needs a current context.
void check_material_shader(const MaterialShader& material);

}  // namespace facet::driver
