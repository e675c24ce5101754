// Modern pipeline, pass 2b: writes each triangle's (triangle, facet) pairs at its offset from the
// exclusive scan, in the same order as pass 1 counted them.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 11) writeonly buffer Pairs { uvec2 pairs[]; };
layout(location = 42) uniform uint triangle_count;

void triangle_eye(uint t, out vec3 p[3]);
uint walk_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) { pairs[at] = uvec2(t, facet); }

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t >= triangle_count || scan[t + 1u] == scan[t]) return;
  vec3 p[3];
  triangle_eye(t, p);
  uint unused;
  walk_coverage(p, t, scan[t], 0xffffffffu, unused);
}
