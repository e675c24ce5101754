// Material shading shared by every renderer: base colour times texture, lit by a fixed sun and
// sky, or shown as authored for unlit materials. Knows nothing of facets or projections, so every
// method shades the same. Output is linear RGB.
in vec3 v_n_world;
in vec2 v_uv;

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

const vec3 d_world_sun = normalize(vec3(0.35, 0.85, 0.4));

void main() {
  vec4 albedo = base_colour;
  if (has_texture) albedo *= texture(base_texture, v_uv);
  float light = 1.0;
  if (unlit == 0u) {
    vec3 n = normalize(v_n_world);
    // Two-sided: thin geometry (leaves, signs) is lit from whichever side faces the viewer.
    if (!gl_FrontFacing) n = -n;
    float sun = max(dot(n, d_world_sun), 0.0);
    float sky = 0.55 + 0.45 * n.y;
    light = 0.75 * sun + 0.35 * sky;
  }
  out_colour = vec4(albedo.rgb * light, albedo.a);
#if WRITE_TRIANGLE_ID
  out_triangle_id = v_triangle_id;
#endif
}
