// Modern pipeline, pass 1: per triangle of the frame's list, the facets it may cover (none when
// culled: back face, non-finite, outside every facet). Counts go to scan[t] (scan[N] = 0 so that
// the exclusive scan leaves the total there). Every facet found is staged, so that the scatter
// copies them and nothing is covered twice: a triangle with at most kKept facets as one run, placed
// by one global atomic per work group; a triangle with more as a chain of chunks (kKept facets and
// the next chunk's offset), each placed by an atomic of its own. Either way stage_offset[t] says
// where (chains with kChained set). A frame whose pairs exceed pair_capacity, or whose staged
// words exceed staged_capacity, sets `overflow` and is run again with more room.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 10) writeonly buffer Scan { uint scan[]; };
layout(std430, binding = 12) buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
  uint staged_total;
};
layout(std430, binding = 17) buffer Staged { uint staged[]; };
layout(std430, binding = 18) writeonly buffer StageOffsets { uint stage_offset[]; };
layout(location = 42) uniform uint triangle_count;
layout(location = 45) uniform uint pair_capacity;
layout(location = 48) uniform uint staged_capacity;  // words of Staged (staged_words in C++)

uint triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint e, uint pair_base, uint wanted, out uint wanted_facet);

const uint kKept = 8u;               // kStagedChunkFacets
const uint kChained = 0x80000000u;   // kStagedChained
const uint kNoChunk = 0xffffffffu;
// The first kKept facets stay here; from the (kKept + 1)-th on, facets go straight to chunks of
// the chain (chain_second onwards), each taken by one atomic when its first facet arrives. The
// first chunk, holding kept[], is placed when the count is known.
uint kept[kKept];
uint chain_second = kNoChunk, chain_tail = kNoChunk;

// A chunk of kKept facets and a link, or kNoChunk (and an overflowing frame) when none is left.
uint new_chunk() {
  uint at = atomicAdd(staged_total, kKept + 1u);
  if (at + kKept + 1u <= staged_capacity) return at;
  overflow = 1u;
  return kNoChunk;
}

void write_pair(uint at, uint t, uint facet) {
  if (at < kKept) {
    kept[at] = facet;
    return;
  }
  uint slot = at % kKept;
  if (slot == 0u) {
    uint chunk = new_chunk();
    if (at == kKept) chain_second = chunk;
    else if (chain_tail != kNoChunk) staged[chain_tail + kKept] = chunk;
    chain_tail = chunk;
  }
  if (chain_tail != kNoChunk) staged[chain_tail + slot] = facet;
}

shared uint group_pairs, group_staged, group_visible, group_base;

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (gl_LocalInvocationIndex == 0u) {
    group_pairs = 0u;
    group_staged = 0u;
    group_visible = 0u;
  }
  barrier();
  uint count = 0u;
  if (t < triangle_count) {
    vec3 p[3];
    uint e = triangle_eye(t, p);
    uint unused;
    count = cover(p, t, e, 0u, 0xffffffffu, unused);
    scan[t] = count;
  } else if (t == triangle_count) {
    scan[t] = 0u;
  }
  bool run = count > 0u && count <= kKept;
  uint offset = 0u;
  if (count > 0u) {
    atomicAdd(group_pairs, count);
    atomicAdd(group_visible, 1u);
  }
  if (run) offset = atomicAdd(group_staged, count);
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    uint before = atomicAdd(pair_total, group_pairs);
    if (before + group_pairs > pair_capacity) overflow = 1u;
    group_base = atomicAdd(staged_total, group_staged);
    atomicAdd(visible_triangles, group_visible);
  }
  barrier();
  if (t >= triangle_count || count == 0u) return;
  if (!run) {
    uint head = new_chunk();
    if (head == kNoChunk) return;
    for (uint k = 0u; k < kKept; ++k) staged[head + k] = kept[k];
    staged[head + kKept] = chain_second;
    stage_offset[t] = head | kChained;
    return;
  }
  uint base = group_base + offset;
  stage_offset[t] = base;
  if (base + count > staged_capacity) {
    overflow = 1u;
    return;
  }
  for (uint k = 0u; k < kKept; ++k) {
    if (k < count) staged[base + k] = kept[k];
  }
}
