// Modern pipeline, pass 1: per triangle of the frame's list, the facets it may cover (none when
// culled: back face, non-finite, outside every facet). Counts go to scan[t] (scan[N] = 0 so that
// the exclusive scan leaves the total there). The facets of a triangle that covers at most kKept
// are staged, as one run at stage_offset[t], so that the scatter copies them instead of finding
// them again; runs are placed by one global atomic per work group. A frame whose pairs exceed
// pair_capacity sets `overflow`, writes nothing past it, and is run again with more room.
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
layout(std430, binding = 17) writeonly buffer Staged { uint staged[]; };
layout(std430, binding = 18) writeonly buffer StageOffsets { uint stage_offset[]; };
layout(location = 42) uniform uint triangle_count;
layout(location = 45) uniform uint pair_capacity;

void triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet);

// Most triangles cover a few facets: those are kept here while counting and staged once their
// run is placed. A triangle with more is left to the scatter, which covers it again in an
// invocation of its own (llvmpipe's loop budget is per invocation).
const uint kKept = 8u;
uint kept[kKept];
void write_pair(uint at, uint t, uint facet) {
  if (at < kKept) kept[at] = facet;
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
    triangle_eye(t, p);
    uint unused;
    count = cover(p, t, 0u, 0xffffffffu, unused);
    scan[t] = count;
  } else if (t == triangle_count) {
    scan[t] = 0u;
  }
  bool staging = count > 0u && count <= kKept;
  uint offset = 0u;
  if (count > 0u) {
    atomicAdd(group_pairs, count);
    atomicAdd(group_visible, 1u);
  }
  if (staging) offset = atomicAdd(group_staged, count);
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    uint before = atomicAdd(pair_total, group_pairs);
    if (before + group_pairs > pair_capacity) overflow = 1u;
    group_base = atomicAdd(staged_total, group_staged);
    atomicAdd(visible_triangles, group_visible);
  }
  barrier();
  if (t >= triangle_count || count == 0u) return;
  if (!staging) {
    stage_offset[t] = 0xffffffffu;
    return;
  }
  // Staged pairs never outnumber all pairs, so they fit whenever the frame does not overflow.
  uint base = group_base + offset;
  stage_offset[t] = base;
  if (base + count > pair_capacity) return;
  for (uint k = 0u; k < kKept; ++k) {
    if (k < count) staged[base + k] = kept[k];
  }
}
