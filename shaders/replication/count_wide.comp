// Modern pipeline, pass 1, the wide pass: the triangles the grid pass queued because their
// buckets list more pieces than one invocation should test (kGridWide: a ground plane under the
// eye, a facade beside it). One work group per triangle; its kWideLanes invocations split the
// listed pieces into consecutive slices, in the order grid_coverage visits them, and test them as
// it does (may_meet). Each invocation counts the pieces of its slice, the counts' exclusive scan
// places each slice, and each invocation tests its slice again to write its pieces there. They are
// staged as count.comp stages them (a run of at most kKept, else a chain of chunks of kKept pieces
// and the next chunk's offset, here contiguous), so that the scatter copies them as any other. The
// walk, which would otherwise take these triangles, runs one invocation each with the other lanes
// of its SIMD row idle: on the dome master at 512x512 and 0.25 px, the 6 to 10 such triangles of a
// frame take the walk 8.6 ms and this pass 0.7 to 0.9 ms (driver/README.md).
const uint kWideLanes = 64u;
layout(local_size_x = kWideLanes) in;

layout(std430, binding = 10) writeonly buffer Scan { uint scan[]; };
layout(std430, binding = 12) buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
  uint staged_total;
};
layout(std430, binding = 17) writeonly buffer Staged { uint staged[]; };
layout(std430, binding = 18) writeonly buffer StageOffsets { uint stage_offset[]; };
layout(location = 45) uniform uint pair_capacity;
layout(location = 48) uniform uint staged_capacity;  // words of Staged (staged_words in C++)
layout(std430, binding = 16) readonly buffer WideQueue {
  uint wide_groups_x, wide_groups_y, wide_groups_z;
  uint wide_count;
  uint wide_queue[];
};
layout(std430, binding = 20) buffer WalkQueue {
  uint walk_groups_x, walk_groups_y, walk_groups_z;
  uint walk_count;
  uint walk_queue[];
};
const uint kWalkRow = 1024u;  // count.comp: work groups per row of a queue's dispatch

const uint kKept = 8u;              // kStagedChunkFacets
const uint kChained = 0x80000000u;  // kStagedChained
const uint kNoChunk = 0xffffffffu;

struct GridQuery {
  vec3 u[3];
  vec4 edge[3];
  uvec4 range;
  uint listed;
};
const uint kGridEmpty = 0u, kGridWalk = 3u;  // replication_lib.comp
uint triangle_eye(uint t, out vec3 p[3]);
uint list_triangle_count();
uint grid_query(vec3 p[3], out GridQuery q);
bool grid_single_listing(GridQuery q);
bool grid_first_listing(GridQuery q, uint i, uint j, uint f);
bool may_meet(vec3 u[3], vec4 edge[3], uint f);
uint grid_word(uint i);
bool grid_periodic();

shared uint lane_found[kWideLanes];
shared uint group_base, group_chunks;

// Where the k-th piece of a triangle staged at `base` goes: a run of at most kKept, else a chain
// of contiguous chunks.
uint staged_at(uint base, bool chained, uint k) {
  return chained ? base + (k / kKept) * (kKept + 1u) + k % kKept : base + k;
}

// The pieces of listed positions [begin, end) (in grid_coverage's order) that the triangle may
// meet; with `base` != kNoChunk, the k-th of them is staged as the triangle's (first + k)-th.
uint cover_slice(GridQuery q, uint begin, uint end, uint base, bool chained, uint first) {
  uint columns = grid_word(2);
  uint first_offset = grid_word(9), facets_offset = grid_word(10);
  bool single = grid_single_listing(q);
  uint found = 0u;
  uint position = 0u;  // listed position of the current run's first piece
  uint run_end = q.range.x + q.range.z;
  for (uint j = q.range.y; j < q.range.y + q.range.w && position < end; ++j) {
    uint row = first_offset + j * columns;
    // A row's buckets are one run, or two where the range wraps past the last column; a run's
    // pieces are contiguous in the bucket lists.
    for (uint r = 0u; r < 2u; ++r) {
      uint column_lo = r == 0u ? q.range.x : 0u;
      uint column_hi =
          r == 0u ? min(run_end, columns) : (run_end > columns ? run_end - columns : 0u);
      if (column_hi <= column_lo) continue;
      uint m_lo = grid_word(row + column_lo), m_hi = grid_word(row + column_hi);
      uint from = max(begin, position), to = min(end, position + (m_hi - m_lo));
      for (uint c = from; c < to; ++c) {
        uint m = m_lo + (c - position);
        uint f = grid_word(facets_offset + m);
        if (!single) {
          // The bucket holding list position m: the last of the run whose first is at most m.
          uint lo = column_lo, hi = column_hi - 1u;
          while (lo < hi) {
            uint middle = (lo + hi + 1u) / 2u;
            if (grid_word(row + middle) <= m) lo = middle; else hi = middle - 1u;
          }
          if (!grid_first_listing(q, lo, j, f)) continue;
        }
        if (!may_meet(q.u, q.edge, f)) continue;
        if (base != kNoChunk) staged[staged_at(base, chained, first + found)] = f;
        ++found;
      }
      position += m_hi - m_lo;
    }
  }
  return found;
}

void main() {
  uint lane = gl_LocalInvocationIndex;
  uint queued = gl_WorkGroupID.y * kWalkRow + gl_WorkGroupID.x;
  if (queued >= wide_count) return;  // the whole group: no barrier is reached
  uint t = wide_queue[queued];
  vec3 p[3];
  triangle_eye(t, p);
  GridQuery q;
  // The grid pass found this triangle wide. Should this program's rounding differ from the grid
  // pass's, a triangle the grid cannot bound after all goes on to the walk, which runs next, and
  // one within a single invocation's bounds is answered here all the same.
  uint status = grid_query(p, q);
  if (status == kGridWalk) {
    if (lane == 0u) {
      uint at = atomicAdd(walk_count, 1u);
      walk_queue[at] = t;
      if (at < kWalkRow) atomicAdd(walk_groups_x, 1u);
      if (at % kWalkRow == 0u) atomicAdd(walk_groups_y, 1u);
    }
    return;  // the whole group: status is the same for every invocation
  }
  bool covers = status != kGridEmpty;
  uint begin = covers ? lane * q.listed / kWideLanes : 0u;
  uint end = covers ? (lane + 1u) * q.listed / kWideLanes : 0u;
  uint mine = cover_slice(q, begin, end, kNoChunk, false, 0u);
  lane_found[lane] = mine;
  barrier();
  if (lane == 0u) {
    uint total = 0u;
    for (uint k = 0u; k < kWideLanes; ++k) {
      uint n = lane_found[k];
      lane_found[k] = total;
      total += n;
    }
    group_base = kNoChunk;
    group_chunks = total > kKept ? (total + kKept - 1u) / kKept : 0u;
    scan[t] = total;
    if (total > 0u) {
      uint before = atomicAdd(pair_total, total);
      if (before + total > pair_capacity) overflow = 1u;
      atomicAdd(visible_triangles, 1u);
      // Within staged_words: a run takes a word a piece, a chain of more than kKept at most two.
      uint words = group_chunks > 0u ? group_chunks * (kKept + 1u) : total;
      uint at = atomicAdd(staged_total, words);
      if (at + words <= staged_capacity) {
        group_base = at;
        stage_offset[t] = group_chunks > 0u ? at | kChained : at;
      } else {
        overflow = 1u;
      }
    }
  }
  barrier();
  uint base = group_base, chunks = group_chunks;
  if (base == kNoChunk) return;
  // Each chunk's last word links the next; the last chunk's holds kNoChunk.
  for (uint c = lane; c < chunks; c += kWideLanes) {
    uint next = c + 1u < chunks ? base + (c + 1u) * (kKept + 1u) : kNoChunk;
    staged[base + c * (kKept + 1u) + kKept] = next;
  }
  if (mine > 0u) cover_slice(q, begin, end, base, chunks > 0u, lane_found[lane]);
}
