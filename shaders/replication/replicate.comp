// Seed pipeline, pass 2b: the replicated index. Triangle t with count c and offset o (exclusive
// scan) gets entries o..o+c-1 = (t, k) for its k-th facet; pass 3 finds that facet again. The
// total goes to the statistics; beyond pair_capacity nothing is written and `overflow` makes
// draw_args.comp draw nothing (the frame is replicated again with room).
layout(local_size_x = 64) in;

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 11) writeonly buffer Pairs { uvec2 pairs[]; };
layout(std430, binding = 12) buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
};
uint list_triangle_count();
layout(location = 45) uniform uint pair_capacity;

const uint kRowGroups = 1024u;  // kListArgsRowGroups

void main() {
  uint triangle_count = list_triangle_count();
  // Rows of kRowGroups work groups (ListArgs: a dispatch may hold 65535 groups a dimension).
  uint t = (gl_WorkGroupID.y * kRowGroups + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
  uint total = scan[triangle_count];
  if (t == 0u) {
    pair_total = total;
    overflow = total > pair_capacity ? 1u : 0u;
  }
  if (t >= triangle_count || total > pair_capacity) return;
  for (uint at = scan[t], k = 0u; at < scan[t + 1u]; ++at, ++k) pairs[at] = uvec2(t, k);
}
