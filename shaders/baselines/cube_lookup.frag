// Cube-map baseline, pass 2: every output pixel looks up its exact eye direction (computed on the
// CPU through the warp inverse) and samples the cube map there: colour filtered (trilinearly when
// the faces have mipmaps), the triangle ID from the nearest level-0 texel.
layout(binding = 0) uniform sampler2D lookup;  // RGBA32F: eye direction xyz, w = 1 if covered
layout(binding = 1) uniform samplerCube colour_cube;
layout(binding = 2) uniform usamplerCube id_cube;

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

// The change of the unit direction to the next covered pixel along `step` (or from the previous
// one), for the mip level: implicit derivatives would take the uncovered neighbours' zero
// directions at the display's edge.
vec3 direction_step(ivec2 p, ivec2 step, vec3 d) {
  ivec2 last = textureSize(lookup, 0) - 1;
  vec4 next = texelFetch(lookup, clamp(p + step, ivec2(0), last), 0);
  if (next.w > 0.5 && p + step == clamp(p + step, ivec2(0), last)) return normalize(next.xyz) - d;
  vec4 previous = texelFetch(lookup, clamp(p - step, ivec2(0), last), 0);
  if (previous.w > 0.5 && p - step == clamp(p - step, ivec2(0), last)) {
    return d - normalize(previous.xyz);
  }
  return vec3(0.0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 v_eye = texelFetch(lookup, p, 0);
  if (v_eye.w < 0.5) discard;
  vec3 d = normalize(v_eye.xyz);
  out_colour = textureGrad(colour_cube, d, direction_step(p, ivec2(1, 0), d),
                           direction_step(p, ivec2(0, 1), d));
  out_triangle_id = texture(id_cube, v_eye.xyz).r;
}
