// Pass 2c: one glDrawArraysIndirect command per material from the exclusive scan. The frame's
// triangle list is grouped by material, so material m's replicas are the contiguous run
// [scan[begin_m], scan[end_m]).
#ifndef VERTICES_PER_REPLICA
#define VERTICES_PER_REPLICA 3
#endif
layout(local_size_x = 64) in;

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 13) readonly buffer MaterialRanges { uvec2 material_ranges[]; };
struct DrawArraysIndirectCommand {
  uint count;
  uint instance_count;
  uint first;
  uint base_instance;
};
layout(std430, binding = 14) writeonly buffer DrawArgs { DrawArraysIndirectCommand args[]; };
layout(std430, binding = 12) readonly buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;  // the pairs are incomplete: draw nothing, the frame runs again
};
layout(location = 43) uniform uint material_count;

void main() {
  uint m = gl_GlobalInvocationID.x;
  if (m >= material_count) return;
  uint first = scan[material_ranges[m].x];
  uint end = overflow != 0u ? first : scan[material_ranges[m].y];
  args[m] = DrawArraysIndirectCommand(VERTICES_PER_REPLICA * (end - first), 1u,
                                      VERTICES_PER_REPLICA * first, 0u);
}
