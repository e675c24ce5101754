// Perspective-image baseline, pass 2: every output pixel looks up where its exact eye direction
// (computed on the CPU through the warp inverse) falls in the one perspective image, and samples
// it there: colour bilinearly, the triangle ID from the nearest texel.
layout(binding = 0) uniform sampler2D lookup;  // RGBA32F: image s, t in [0, 1]; w = 1 if covered
layout(binding = 1) uniform sampler2D colour_image;
layout(binding = 2) uniform usampler2D id_image;

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

void main() {
  vec4 st = texelFetch(lookup, ivec2(gl_FragCoord.xy), 0);
  if (st.w < 0.5) discard;
  out_colour = textureLod(colour_image, st.xy, 0.0);
  ivec2 size = textureSize(id_image, 0);
  ivec2 texel = clamp(ivec2(floor(st.xy * vec2(size))), ivec2(0), size - 1);
  out_triangle_id = texelFetch(id_image, texel, 0).r;
}
