// Material shading shared by every renderer: gathers MaterialInput (scene/material_interface.frag)
// from the vertex stage's outputs and the scene material's uniforms, calls shade() of the
// material linked beside it as a second fragment shader object (scene/materials/*.frag or a
// user's file: driver/material_shader.hpp), and writes the colour (linear RGB) and the triangle
// ID. Knows nothing of facets or projections, so every method shades the same; compiled with the
// interface in front, as every material is. sun_and_sky() is scene/sun_and_sky.frag's. The GLC
// ray cast gathers the same inputs from its ray's hit instead (glc/glc_hit.frag).
in vec3 v_n_world;
in vec2 v_uv;
in vec3 v_p_world;
in vec3 v_p_eye;
in vec3 v_barycentric;

layout(location = 8) uniform vec4 base_colour;  // linear RGBA
layout(location = 9) uniform bool has_texture;
layout(binding = 0) uniform sampler2D base_texture;  // sRGB texture: sampling returns linear
// Bound per material by GpuScene::bind_material_texture (binding: material_shading_binding).
layout(std140, binding = 0) uniform MaterialShading {
  uint unlit;  // 1: base colour times texture as authored, no lighting
};

layout(location = 0) out vec4 out_colour;

// Renderers that keep a triangle-ID image (driver/render_method.hpp) define WRITE_TRIANGLE_ID 1
// and pass the ID from their last vertex stage; it goes to draw buffer 1 (R32UI) unchanged.
#ifndef WRITE_TRIANGLE_ID
#define WRITE_TRIANGLE_ID 0
#endif
#if WRITE_TRIANGLE_ID
flat in uint v_triangle_id;
layout(location = 1) out uint out_triangle_id;
#endif

// Renderers that write more per sample define EXTRA_OUTPUTS 1 and link a fragment shader object
// defining write_extra_outputs(), called after the colour and the ID are written (the GLC
// two-pass method's samples: glc/glc_sample.frag).
#ifndef EXTRA_OUTPUTS
#define EXTRA_OUTPUTS 0
#endif
#if EXTRA_OUTPUTS
void write_extra_outputs();
#endif

void main() {
  MaterialInput m;
  m.p_world = v_p_world;
  vec3 n = normalize(v_n_world);
  // Two-sided: thin geometry (leaves, signs) is lit from whichever side faces the viewer.
  m.n_world = gl_FrontFacing ? n : -n;
  m.uv = v_uv;
  m.barycentric = v_barycentric;
  // Derivatives here, in uniform control flow, whatever the material does with them.
  vec3 gradient = sqrt(dFdx(v_barycentric) * dFdx(v_barycentric) +
                       dFdy(v_barycentric) * dFdy(v_barycentric));
  m.edge_px = v_barycentric / max(gradient, vec3(1e-9));
  m.distance_m = length(v_p_eye);
  m.depth = gl_FragCoord.z;
  m.q_px = gl_FragCoord.xy;
#if WRITE_TRIANGLE_ID
  m.triangle_id = v_triangle_id;
#else
  m.triangle_id = 0u;
#endif
  m.base_colour = base_colour;
  if (has_texture) m.base_colour *= texture(base_texture, v_uv);
  m.unlit = unlit != 0u;
  out_colour = shade(m);
#if WRITE_TRIANGLE_ID
  out_triangle_id = v_triangle_id;
#endif
#if EXTRA_OUTPUTS
  write_extra_outputs();
#endif
}
