// GLC two-pass rasterization ("glc-2pass"), pass 2's fragments: each takes the colour and the
// triangle ID of the pass-1 sample nearest to it in the sample grid (IDs are not blended), and is
// kept where its pixel belongs to the piece being drawn (the camera's piece map) and that sample
// saw a triangle. Depth is interpolated between the samples' reversed-Z depths; the depth test
// keeps the nearest surface.
layout(binding = 1) uniform sampler2D sample_colour;  // sRGB: texelFetch returns linear
layout(binding = 2) uniform usampler2D sample_ids;
layout(binding = 3) uniform isampler2D piece_of_pixel;  // GL rows (row 0 at the bottom)
layout(location = 3) uniform int piece;

noperspective in vec2 v_texel;

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

void main() {
  if (texelFetch(piece_of_pixel, ivec2(gl_FragCoord.xy), 0).r != piece) discard;
  const ivec2 nearest = ivec2(floor(v_texel + 0.5));
  const uint id = texelFetch(sample_ids, nearest, 0).r;
  if (id == 0u) discard;
  out_colour = texelFetch(sample_colour, nearest, 0);
  out_triangle_id = id;
}
