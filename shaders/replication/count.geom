// Seed pipeline, pass 1: a geometry shader counts each triangle's facets into transform
// feedback, one uint per triangle in list order (rasterizer discard on).
layout(points) in;
layout(points, max_vertices = 1) out;

flat in uint v_index[];
layout(xfb_buffer = 0, xfb_offset = 0) out uint tf_count;

layout(std430, binding = 12) buffer Stats { uint visible_triangles; };

uint triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint e, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) {}

void main() {
  uint t = v_index[0];
  vec3 p[3];
  uint e = triangle_eye(t, p);
  uint unused;
  tf_count = cover(p, t, e, 0xffffffffu, 0xffffffffu, unused);
  if (tf_count > 0u) atomicAdd(visible_triangles, 1u);
  EmitVertex();
  EndPrimitive();
}
