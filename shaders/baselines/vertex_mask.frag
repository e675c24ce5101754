// Per-vertex projection baseline: output pixels whose centre has no covered preimage (FORMATS.md
// §2 coverage, decided exactly on the CPU through the warp inverse) get the nearest depth before
// the scene is drawn, so no scene fragment passes there (reversed-Z, GL_GREATER); a second run
// with depth_value 0 puts the far depth back afterwards. Colour writes are off during both.
layout(binding = 0) uniform sampler2D coverage_mask;  // R8, GL rows: 1 where covered
layout(location = 0) uniform float depth_value;

void main() {
  if (texelFetch(coverage_mask, ivec2(gl_FragCoord.xy), 0).r >= 0.5) discard;
  gl_FragDepth = depth_value;
}
