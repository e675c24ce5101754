// Cube-map baseline, pass 2: every output pixel looks up its exact eye direction (computed on the
// CPU through the warp inverse) and samples the cube map there: colour filtered, the triangle ID
// from the nearest texel.
layout(binding = 0) uniform sampler2D lookup;  // RGBA32F: eye direction xyz, w = 1 if covered
layout(binding = 1) uniform samplerCube colour_cube;
layout(binding = 2) uniform usamplerCube id_cube;

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

void main() {
  vec4 v_eye = texelFetch(lookup, ivec2(gl_FragCoord.xy), 0);
  if (v_eye.w < 0.5) discard;
  out_colour = texture(colour_cube, v_eye.xyz);
  out_triangle_id = texture(id_cube, v_eye.xyz).r;
}
