// GLC rasterization (the "glc" method), pass 1: one screen-aligned quad per (triangle, piece), the
// triangle's conservative pixel bound in that GLC piece clipped to the piece's region (computed on
// the CPU, Glc::triangle_bounds). Vertices are pulled: vertex 6k..6k+5 draw quad k.
struct Quad {
  vec4 box;  // x0, y0, x1, y1 in GL window coordinates (y up), continuous
  vec4 a, b, c;  // the triangle's vertices (eye frame; w unused)
  uvec4 ids;     // triangle ID, piece, material, unused
};
layout(std430, binding = 0) readonly buffer Quads { Quad quads[]; };
layout(location = 0) uniform vec2 output_size;

flat out uint quad_index;

void main() {
  const uint k = uint(gl_VertexID) / 6u;
  const uint corner = uint(gl_VertexID) % 6u;
  // Two triangles: (0, 1, 2), (2, 1, 3) over corners (x0,y0) (x1,y0) (x0,y1) (x1,y1).
  const uint corners[6] = uint[6](0u, 1u, 2u, 2u, 1u, 3u);
  const uint c = corners[corner];
  const vec4 box = quads[k].box;
  const vec2 p = vec2((c & 1u) != 0u ? box.z : box.x, (c & 2u) != 0u ? box.w : box.y);
  quad_index = k;
  gl_Position = vec4(2.0 * p / output_size - 1.0, 0.0, 1.0);
}
