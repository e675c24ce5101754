// Modern pipeline, pass 1: per triangle of the frame's list, the facets it may cover (none when
// culled: back face, non-finite, outside every facet). Counts go to scan[t] (scan[N] = 0 so that
// the exclusive scan leaves the total there). Every facet found is staged, so that the scatter
// copies them and nothing is covered twice: a triangle with at most kKept facets as one run, placed
// by one global atomic per work group; a triangle with more as a chain of chunks (kKept facets and
// the next chunk's offset), each placed by an atomic of its own. Either way stage_offset[t] says
// where (chains with kChained set). A frame whose pairs exceed pair_capacity, or whose staged
// words exceed staged_capacity, sets `overflow` and is run again with more room.
// Four passes, each writing the same counts and staging for the triangles it answers:
// - the cull pass (one invocation per list triangle) culls, gives a triangle of an object inside
//   one piece that piece, and queues the others for the grid pass;
// - the grid pass (GRID_PASS: one invocation per queued triangle) takes what the coverage grid
//   answers within one invocation's bounds, and queues the rest for the wide pass
//   (replication/count_wide.comp: a work group per triangle shares its candidates) or, where the
//   grid cannot bound the triangle, for the walk pass;
// - the walk pass (WALK_PASS: one work group per queued triangle) walks the hierarchy for them.
// Each queue carries its pass's indirect dispatch. llvmpipe runs both sides of every branch for
// all lanes of a SIMD row, so the queues are what keep a pass's cost to the triangles that need
// it: in one pass, a back face or a triangle of an object inside one piece cost the grid's whole
// test (pass 1 of the cylinder at 400x300 and 1 px: 4.5 ms in one pass, 3.6 ms in three). With
// WALK_EVERY_TRIANGLE the cull pass walks every triangle itself
// (RenderSettings::coverage = walk, the reference) and queues none.
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 64
#endif
#if defined(WALK_PASS) && defined(GRID_PASS)
#error one pass per program
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
// The wide pass's (replication/count_wide.comp) indirect dispatch, as the walk pass's, then the
// queue.
layout(std430, binding = 16) buffer WideQueue {
  uint wide_groups_x, wide_groups_y, wide_groups_z;
  uint wide_count;
  uint wide_queue[];
};
// The grid pass's indirect dispatch, one work group per LOCAL_SIZE queued triangles in rows of
// kWalkRow groups, then the queue.
layout(std430, binding = 21) buffer GridQueue {
  uint grid_groups_x, grid_groups_y, grid_groups_z;
  uint grid_count;
  uint grid_queue[];
};

const uint kNoPiece = 0xffffffffu;  // ListEntry::sole_piece of an entry without one
uint triangle_eye(uint t, out vec3 p[3]);
bool triangle_may_cover(vec3 p[3]);
uvec4 list_entry(uint e);
uint list_triangle_count();
bool grid_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet,
                   out uint found, out uint status);
const uint kGridWide = 2u;  // replication_lib.comp
uint walk_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);

const uint kKept = 8u;               // kStagedChunkFacets
const uint kChained = 0x80000000u;   // kStagedChained
const uint kNoChunk = 0xffffffffu;
// The first kKept facets stay here; from the (kKept + 1)-th on, facets go straight to chunks of
// the chain (chain_second onwards), each taken by one atomic when its first facet arrives. The
// first chunk, holding kept(0) to kept(kKept - 1), is placed when the count is known. Two
// vectors, not an array: each lane writes its own slot, and llvmpipe stores into an array at a
// per-lane index one lane at a time (pass 1 of the dome master at 512x512 and 0.25 px: 10.3-10.4
// ms with the array, 8.3-9.0 ms this way).
uvec4 kept_low = uvec4(0u), kept_high = uvec4(0u);
uint kept(uint k) { return k < 4u ? kept_low[k] : kept_high[k - 4u]; }
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
    // Slot `at` of the eight: a select per component.
    kept_low = mix(kept_low, uvec4(facet), equal(uvec4(at), uvec4(0u, 1u, 2u, 3u)));
    kept_high = mix(kept_high, uvec4(facet), equal(uvec4(at), uvec4(4u, 5u, 6u, 7u)));
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
  uint triangle_count = list_triangle_count();
#if defined(WALK_PASS)
  uint queued = gl_WorkGroupID.y * kWalkRow + gl_WorkGroupID.x;
  uint t = queued < walk_count ? walk_queue[queued] : triangle_count + 1u;
#elif defined(GRID_PASS)
  uint queued =
      (gl_WorkGroupID.y * kWalkRow + gl_WorkGroupID.x) * LOCAL_SIZE + gl_LocalInvocationIndex;
  uint t = queued < grid_count ? grid_queue[queued] : triangle_count + 1u;
#else
  // Rows of kWalkRow work groups (ListArgs: a dispatch may hold 65535 groups a dimension).
  uint t = (gl_WorkGroupID.y * kWalkRow + gl_WorkGroupID.x) * LOCAL_SIZE + gl_LocalInvocationIndex;
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
#if defined(GRID_PASS)
    uint status;
    if (!grid_coverage(p, t, 0u, 0xffffffffu, unused, count, status)) {
      count = 0u;
      if (status == kGridWide) {
        uint at = atomicAdd(wide_count, 1u);
        wide_queue[at] = t;
        if (at < kWalkRow) atomicAdd(wide_groups_x, 1u);
        if (at % kWalkRow == 0u) atomicAdd(wide_groups_y, 1u);
      } else {
        uint at = atomicAdd(walk_count, 1u);
        walk_queue[at] = t;
        if (at < kWalkRow) atomicAdd(walk_groups_x, 1u);
        if (at % kWalkRow == 0u) atomicAdd(walk_groups_y, 1u);
      }
    }
#else
    uint sole = list_entry(e).z;
    if (!triangle_may_cover(p)) {
      count = 0u;
    } else if (sole != kNoPiece) {
      write_pair(0u, t, sole);
      count = 1u;
    } else {
      uint at = atomicAdd(grid_count, 1u);
      grid_queue[at] = t;
      if (at % uint(LOCAL_SIZE) == 0u) {
        uint group = at / uint(LOCAL_SIZE);
        if (group < kWalkRow) atomicAdd(grid_groups_x, 1u);
        if (group % kWalkRow == 0u) atomicAdd(grid_groups_y, 1u);
      }
    }
#endif
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
    for (uint k = 0u; k < kKept; ++k) staged[head + k] = kept(k);
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
  // To the run's length, not kKept: llvmpipe runs a loop until its last lane is done, and a
  // masked store still visits all eight lanes.
  for (uint k = 0u; k < count; ++k) staged[base + k] = kept(k);
}
