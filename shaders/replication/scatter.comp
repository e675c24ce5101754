// Modern pipeline, pass 2b: writes each triangle's (triangle, facet) pairs at its offset from the
// exclusive scan, in the order pass 1 found them: a copy of the facets pass 1 staged, or, for a
// triangle that covers more than pass 1 keeps, its coverage found again. The list's order,
// grouped by material, is the draw order. Nothing is written for a frame that overflowed.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 11) writeonly buffer Pairs { uvec2 pairs[]; };
layout(std430, binding = 12) readonly buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
  uint staged_total;
};
layout(std430, binding = 17) readonly buffer Staged { uint staged[]; };
layout(std430, binding = 18) readonly buffer StageOffsets { uint stage_offset[]; };
layout(location = 42) uniform uint triangle_count;
layout(location = 45) uniform uint pair_capacity;

void triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) {
  if (at < pair_capacity) pairs[at] = uvec2(t, facet);
}

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t >= triangle_count || overflow != 0u) return;
  uint first = scan[t], count = scan[t + 1u] - first;
  if (count == 0u) return;
  uint source = stage_offset[t];
  if (source == 0xffffffffu) {
    vec3 p[3];
    triangle_eye(t, p);
    uint unused;
    cover(p, t, first, 0xffffffffu, unused);
    return;
  }
  // Eight pairs per iteration: a triangle over thousands of facets stays within llvmpipe's loop
  // budget per invocation.
  for (uint k = 0u; k < count; k += 8u) {
    for (uint m = 0u; m < 8u; ++m) {
      if (k + m < count) pairs[first + k + m] = uvec2(t, staged[source + k + m]);
    }
  }
}
