// Modern pipeline, pass 2b: writes each triangle's replicas (GpuReplica: its first corner's index,
// the piece, its object and ID) at its offset from the exclusive scan, in the order pass 1 found
// its pieces, by copying what pass 1 staged: one run, or a chain of chunks (kKept facets, then the
// next chunk's offset) where stage_offset has kChained set. The list's order, grouped by
// material, is the draw order. Nothing is written for a frame that overflowed.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 11) writeonly buffer Pairs { uvec4 replicas[]; };
layout(std430, binding = 12) readonly buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
  uint staged_total;
};
// Pass 1's and the scan's results, read as buffer textures (R32UI): llvmpipe fetches a texel for
// every SIMD lane at once, where it loads shader storage one lane at a time.
layout(binding = 16) uniform usamplerBuffer scan_texels;
layout(binding = 17) uniform usamplerBuffer staged_texels;
layout(binding = 18) uniform usamplerBuffer stage_offset_texels;
uint scan(uint t) { return texelFetch(scan_texels, int(t)).x; }
uint staged(uint at) { return texelFetch(staged_texels, int(at)).x; }
uint list_triangle_count();

const uint kKept = 8u;              // kStagedChunkFacets
const uint kChained = 0x80000000u;  // kStagedChained

uint entry_of_triangle(uint t);
uint vertex_index_of(uint e, uint t);
uint object_of(uint e);
uint triangle_id(uint e, uint t);

const uint kRowGroups = 1024u;  // kListArgsRowGroups

void main() {
  uint triangle_count = list_triangle_count();
  // Rows of kRowGroups work groups (ListArgs: a dispatch may hold 65535 groups a dimension).
  uint t = (gl_WorkGroupID.y * kRowGroups + gl_WorkGroupID.x) * uint(LOCAL_SIZE) + gl_LocalInvocationIndex;
  if (t >= triangle_count || overflow != 0u) return;
  uint first = scan(t), count = scan(t + 1u) - first;
  if (count == 0u) return;
  uint e = entry_of_triangle(t);
  uvec4 replica = uvec4(vertex_index_of(e, t), 0u, object_of(e), triangle_id(e, t));
  uint source = texelFetch(stage_offset_texels, int(t)).x;
  bool chained = (source & kChained) != 0u;
  source &= ~kChained;
  if (!chained) {
    // A run: as many iterations as pairs (llvmpipe runs a loop until its last lane is done, and a
    // masked store still visits all eight lanes).
    for (uint m = 0u; m < count; ++m) {
      replica.y = staged(source + m);
      replicas[first + m] = replica;
    }
    return;
  }
  // A chain, eight pairs per iteration of an unrolled inner loop: a triangle over thousands of
  // facets stays within llvmpipe's loop budget per invocation.
  for (uint k = 0u; k < count; k += kKept) {
    for (uint m = 0u; m < kKept; ++m) {
      if (k + m < count) {
        replica.y = staged(source + m);
        replicas[first + k + m] = replica;
      }
    }
    source = staged(source + kKept);
  }
}
