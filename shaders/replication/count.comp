// Modern pipeline, pass 1: per triangle of the frame's list, the facets it may cover (none when
// culled: back face, non-finite, outside every facet). Counts go to scan[t] (scan[N] = 0 so that
// the exclusive scan leaves the total there). Every facet found is staged, so that the scatter
// copies them and nothing is covered twice: a triangle with at most kKept facets as one run, placed
// by one global atomic per work group; a triangle with more as a chain of chunks (kKept facets and
// the next chunk's offset), each placed by an atomic of its own. Either way stage_offset[t] says
// where (chains with kChained set). A frame whose pairs exceed pair_capacity, or whose staged
// words exceed staged_capacity, sets `overflow` and is run again with more room.
// Two programs: the grid pass (one invocation per list triangle) takes what the sole pieces and
// the coverage grid answer and queues the other triangles, with the indirect arguments of the
// walk pass (WALK_PASS: one invocation per queued triangle), which walks the hierarchy for them.
// Both write the same counts and staging. With WALK_EVERY_TRIANGLE the first pass walks every
// triangle itself (RenderSettings::coverage = walk, the reference) and queues none.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
#ifdef WALK_PASS
// One triangle a work group. llvmpipe runs a work group's invocations as SIMD lanes and counts
// every loop iteration of the group against one budget of 65535 (LP_MAX_TGSI_LOOP_ITERATIONS);
// triangles that each cover thousands of the 28,800-facet dome's facets, walked side by side,
// exceeded it and lost facets.
layout(local_size_x = 1) in;
#else
layout(local_size_x = LOCAL_SIZE) in;
#endif

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
// The walk pass's indirect dispatch, one work group per queued triangle in rows of
// kWalkRow (work group counts may be capped at 65535 per dimension), then the queue.
layout(std430, binding = 20) buffer WalkQueue {
  uint walk_groups_x, walk_groups_y, walk_groups_z;
  uint walk_count;
  uint walk_queue[];
};
const uint kWalkRow = 1024u;

const uint kNeedsWalk = 0xfffffffeu;
uint triangle_eye(uint t, out vec3 p[3]);
uint cover_without_walk(vec3 p[3], uint t, uint e, uint pair_base, uint wanted,
                        out uint wanted_facet);
uint walk_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);

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
#ifdef WALK_PASS
  uint queued = gl_WorkGroupID.y * kWalkRow + gl_WorkGroupID.x;
  uint t = queued < walk_count ? walk_queue[queued] : triangle_count + 1u;
#else
  uint t = gl_GlobalInvocationID.x;
#endif
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
#if defined(WALK_PASS) || defined(WALK_EVERY_TRIANGLE)
    count = walk_coverage(p, t, 0u, 0xffffffffu, unused);
#else
    count = cover_without_walk(p, t, e, 0u, 0xffffffffu, unused);
    if (count == kNeedsWalk) {
      count = 0u;
      uint at = atomicAdd(walk_count, 1u);
      walk_queue[at] = t;
      if (at < kWalkRow) atomicAdd(walk_groups_x, 1u);
      if (at % kWalkRow == 0u) atomicAdd(walk_groups_y, 1u);
    }
#endif
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
  if (count == 0u) return;
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
