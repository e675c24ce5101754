// The default lighting, for any material to call (declared in scene/material_interface.frag): the
// base colour under a fixed sun and sky in the world frame, or as authored when unlit. A shader
// object of its own in every material program (driver/material_shader.hpp), beside the stage that
// gathers MaterialInput (scene/material.frag, or glc/glc_hit.frag for the GLC ray cast).
const vec3 d_world_sun = normalize(vec3(0.35, 0.85, 0.4));

vec3 sun_and_sky(MaterialInput m) {
  if (m.unlit) return m.base_colour.rgb;
  float sun = max(dot(m.n_world, d_world_sun), 0.0);
  float sky = 0.55 + 0.45 * m.n_world.y;
  return m.base_colour.rgb * (0.75 * sun + 0.35 * sky);
}
