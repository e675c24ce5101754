// Pass 2c: the indirect draw commands of pass 3 from the exclusive scan. The frame's triangle
// list is grouped by material, so material m's replicas are the contiguous run
// [scan[begin_m], scan[end_m]). Material m owns commands [m·draws_per_material, (m + 1)·
// draws_per_material), each of at most replicas_per_draw replicas, and draw_counts[m] of them
// are used (glMultiDrawArraysIndirectCount; commands past the count are not read).
#ifndef VERTICES_PER_REPLICA
#define VERTICES_PER_REPLICA 3
#endif
layout(local_size_x = 64) in;  // x: a material's commands; work group y: the material

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 13) readonly buffer MaterialRanges { uvec2 material_ranges[]; };
struct DrawArraysIndirectCommand {
  uint count;
  uint instance_count;
  uint first;
  uint base_instance;
};
layout(std430, binding = 14) writeonly buffer DrawArgs { DrawArraysIndirectCommand args[]; };
layout(std430, binding = 19) writeonly buffer DrawCounts { uint draw_counts[]; };
layout(std430, binding = 12) readonly buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;  // the pairs are incomplete: draw nothing, the frame runs again
};
layout(location = 43) uniform uint material_count;
layout(location = 46) uniform uint draws_per_material;
layout(location = 47) uniform uint replicas_per_draw;

void main() {
  uint m = gl_WorkGroupID.y, j = gl_GlobalInvocationID.x;
  if (m >= material_count || j >= draws_per_material) return;
  uint first = scan[material_ranges[m].x];
  uint replicas = overflow != 0u ? 0u : scan[material_ranges[m].y] - first;
  uint used = (replicas + replicas_per_draw - 1u) / replicas_per_draw;
  if (j == 0u) draw_counts[m] = used;
  if (j >= used) return;
  uint begin = j * replicas_per_draw;
  args[m * draws_per_material + j] = DrawArraysIndirectCommand(
      VERTICES_PER_REPLICA * min(replicas_per_draw, replicas - begin), 1u,
      VERTICES_PER_REPLICA * (first + begin), 0u);
}
