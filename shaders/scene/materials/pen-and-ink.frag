// Pen-and-ink hatching in screen space: the tone, the lighting of the surface (sun and sky) times
// half the sRGB-encoded lightness of its colour, is drawn as up to three layers of parallel lines
// in output pixels (one diagonal below 0.7, the other diagonal below 0.45, horizontal below
// 0.25) in ink on paper. Lines are 1 px wide every 6 px, antialiased over one pixel; being laid
// out in output pixels, they run on unbroken over facet seams.
const vec3 kPaper = vec3(0.96, 0.94, 0.88), kInk = vec3(0.05, 0.05, 0.08);
const vec3 kLuma = vec3(0.2126, 0.7152, 0.0722);
const float kSpacingPx = 6.0, kLinePx = 1.0;

// Ink of the lines perpendicular to the unit vector `across`, one every kSpacingPx.
float hatch(vec2 q_px, vec2 across) {
  float t = fract(dot(q_px, across) / kSpacingPx);
  float distance_px = min(t, 1.0 - t) * kSpacingPx;
  return clamp(0.5 * kLinePx - distance_px + 0.5, 0.0, 1.0);
}

vec4 shade(MaterialInput m) {
  MaterialInput white = m;
  white.base_colour = vec4(1.0);
  float light = dot(sun_and_sky(white), kLuma);
  float lightness = pow(dot(m.base_colour.rgb, kLuma), 1.0 / 2.2);
  float tone = light * mix(1.0, lightness, 0.5);
  float ink = 0.0;
  if (tone < 0.7) ink = max(ink, hatch(m.q_px, vec2(0.70710678, 0.70710678)));
  if (tone < 0.45) ink = max(ink, hatch(m.q_px, vec2(0.70710678, -0.70710678)));
  if (tone < 0.25) ink = max(ink, hatch(m.q_px, vec2(0.0, 1.0)));
  return vec4(mix(kPaper, kInk, ink), m.base_colour.a);
}
