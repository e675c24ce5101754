// Depth-dependent solid wireframe: the lit surface with every scene triangle's edges drawn as
// dark strokes of a width in output pixels that falls with distance, 3 px at 10 m and nearer,
// as 30 / distance beyond, and never under 1 px. A stroke is the set of points within half the
// width of an edge (MaterialInput::edge_px, from the barycentric coordinates' screen gradient);
// the two triangles that share an edge each draw their half. Its border is antialiased over one
// pixel, so a stroke's ink summed across it is its width.
const float kNearWidthPx = 3.0, kNearDistanceM = 10.0, kMinWidthPx = 1.0;
const vec3 kInk = vec3(0.02, 0.02, 0.03);

vec4 shade(MaterialInput m) {
  float width_px = clamp(kNearWidthPx * kNearDistanceM / m.distance_m, kMinWidthPx, kNearWidthPx);
  float d = min(m.edge_px.x, min(m.edge_px.y, m.edge_px.z));
  float ink = clamp(0.5 * width_px - d + 0.5, 0.0, 1.0);
  return vec4(mix(sun_and_sky(m), kInk, ink), m.base_colour.a);
}
