// Shows an output's encoded bytes in a window, pixel for pixel when the viewport has the output's
// size (a fullscreen window on its projector); otherwise nearest texels, never filtered.
layout(binding = 0) uniform sampler2D output_bytes;  // RGBA8 view of the output colour
layout(location = 0) uniform ivec2 viewport_origin;
layout(location = 1) uniform vec2 output_per_viewport_pixel;

layout(location = 0) out vec4 colour;

void main() {
  ivec2 pixel = ivec2((gl_FragCoord.xy - vec2(viewport_origin)) * output_per_viewport_pixel);
  colour = texelFetch(output_bytes, min(pixel, textureSize(output_bytes, 0) - 1), 0);
}
