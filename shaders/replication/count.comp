// Modern pipeline, pass 1: per triangle of the frame's list, how many facets it may cover
// (0 when culled: back face, non-finite, outside every facet). Counts go to scan[t]; scan[N] = 0
// so that the exclusive scan leaves the total there.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 10) writeonly buffer Scan { uint scan[]; };
layout(std430, binding = 12) buffer Stats { uint visible_triangles; };
layout(location = 42) uniform uint triangle_count;

void triangle_eye(uint t, out vec3 p[3]);
uint walk_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) {}

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t > triangle_count) return;
  if (t == triangle_count) {
    scan[t] = 0u;
    return;
  }
  vec3 p[3];
  triangle_eye(t, p);
  uint unused;
  uint count = walk_coverage(p, t, 0xffffffffu, 0xffffffffu, unused);
  scan[t] = count;
  if (count > 0u) atomicAdd(visible_triangles, 1u);
}
