// Blend and black level of one projector output, in place: out = c·α·(1−β) + β in linear light
// (MPCDI's composite), then encoded for the projector. One work group per listed 16×16 tile, so
// pixels whose weight is 1 and black level 0 are never touched when the encoding is sRGB.
#ifndef TILE
#define TILE 16
#endif
#ifndef POWER_ENCODING  // 1: encode with pow(x, 1/gamma); 0: the sRGB transfer function
#define POWER_ENCODING 0
#endif
#ifndef HAS_BLACK
#define HAS_BLACK 0
#endif
layout(local_size_x = TILE, local_size_y = TILE) in;

// The output colour as raw bytes (an RGBA8 view of its SRGB8_ALPHA8 storage).
layout(binding = 0, rgba8) uniform coherent image2D colour;
layout(binding = 0) uniform sampler2D alpha;  // RGB weights, GL row order (row 0 at the bottom)
layout(binding = 1) uniform sampler2D black;  // RGB black levels, same layout

layout(std430, binding = 0) readonly buffer Tiles {
  uvec2 tile_origin[];  // pixel of each tile's lower-left corner
};

layout(location = 0) uniform float inverse_gamma;

vec3 srgb_decode(vec3 e) {
  return mix(e / 12.92, pow((e + 0.055) / 1.055, vec3(2.4)), greaterThan(e, vec3(0.04045)));
}
vec3 srgb_encode(vec3 l) {
  return mix(l * 12.92, 1.055 * pow(l, vec3(1.0 / 2.4)) - 0.055, greaterThan(l, vec3(0.0031308)));
}

void main() {
  ivec2 pixel = ivec2(tile_origin[gl_WorkGroupID.x] + gl_LocalInvocationID.xy);
  if (any(greaterThanEqual(pixel, imageSize(colour)))) return;
  vec4 stored = imageLoad(colour, pixel);
  vec3 linear = srgb_decode(stored.rgb);
  vec3 weight = texelFetch(alpha, pixel, 0).rgb;
#if HAS_BLACK
  vec3 beta = texelFetch(black, pixel, 0).rgb;
#else
  vec3 beta = vec3(0.0);
#endif
  vec3 composite = clamp(linear * weight * (1.0 - beta) + beta, 0.0, 1.0);
#if POWER_ENCODING
  vec3 encoded = pow(composite, vec3(inverse_gamma));
#else
  vec3 encoded = srgb_encode(composite);
#endif
  imageStore(colour, pixel, vec4(encoded, stored.a));
}
