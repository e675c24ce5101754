// The frame's triangle list of one output, built on the GPU (RenderSettings::triangle_list), in
// the layout FacetMethodBase builds on the CPU: an entry for every record, in material order (an
// entry of a culled object holds no triangles), the list's header, then its block table. Three
// programs, dispatched in order with the prefix scan between the second and the third:
// - OBJECT_PASS, one invocation per object: kCulled unless its eye-frame bounding sphere may meet
//   a facet's guarded pyramid (sphere_may_meet_facets in replication_lib.comp), else its sole
//   piece (sole_piece_of_sphere) or kNoPiece;
// - COUNT_PASS, one per entry: its state (its object's, unless its cluster faces away, or its
//   cluster's own sphere meets no facet or lies in one piece alone), and its record's triangles
//   when not culled, else 0, into the scan buffer (and 0 after the last entry, so that the
//   exclusive scan ends with the total), and the triangles with a sole piece into the statistics;
// - WRITE_PASS, one per entry, block and material: the entries, the block table, the material
//   ranges, the header and the indirect arguments of the passes that follow (ListArgs), and the
//   list's triangles into the statistics.
#if defined(OBJECT_PASS) && (defined(COUNT_PASS) || defined(WRITE_PASS))
#error one pass per program
#endif
#if defined(COUNT_PASS) && defined(WRITE_PASS)
#error one pass per program
#endif
layout(local_size_x = 64) in;

const uint kNoPiece = 0xffffffffu;  // ListEntry::sole_piece of an entry without one
const uint kCulled = 0xfffffffeu;   // an object's state when it meets no facet
uvec4 record(uint r);
// Statistics words 4 and 5: the list's triangles, and those of entries with a sole piece.
layout(std430, binding = 12) buffer Stats {
  uint visible_triangles;
  uint pair_total;
  uint overflow;
  uint staged_total;
  uint list_triangles;
  uint list_triangles_sole_piece;
};

#if defined(OBJECT_PASS)
// Eye frame: centre (metres), radius grown to cover float rounding; radius < 0: no vertices.
layout(std430, binding = 23) readonly buffer ObjectSpheres { vec4 object_spheres[]; };
layout(std430, binding = 24) writeonly buffer ObjectVisible { uint object_state[]; };
layout(location = 50) uniform uint object_count;
// 1: objects may take a sole piece (grid coverage, cell buckets whose pads are under a cell).
layout(location = 52) uniform uint sole_pieces;
bool sphere_may_meet_facets(vec3 centre, float radius);
uint sole_piece_of_sphere(vec3 centre, float radius);

void main() {
  uint o = gl_GlobalInvocationID.x;
  if (o == 0u) list_triangles_sole_piece = 0u;
  if (o >= object_count) return;
  vec4 sphere = object_spheres[o];
  uint state = kCulled;
  if (sphere.w >= 0.0 && sphere_may_meet_facets(sphere.xyz, sphere.w))
    state = sole_pieces != 0u ? sole_piece_of_sphere(sphere.xyz, sphere.w) : kNoPiece;
  object_state[o] = state;
}

#else
layout(location = 40) uniform uint list_entries;  // replication_lib.comp: every record
layout(std430, binding = 26) readonly buffer EntryRecords { uint entry_records[]; };

#if defined(COUNT_PASS)
layout(std430, binding = 10) writeonly buffer Scan { uint scan[]; };
layout(std430, binding = 24) readonly buffer ObjectVisible { uint object_state[]; };
layout(std430, binding = 29) writeonly buffer EntryStates { uint entry_state[]; };
// Per record, where records are clusters (cluster_culling != 0): the eye-frame sphere as the
// objects' (FacetMethodBase::cluster_spheres_buffer_), or in w kClusterCulledAlways (facing away,
// or no triangle) or kClusterAsObject (culled as its object is).
layout(std430, binding = 28) readonly buffer ClusterSpheres { vec4 cluster_spheres[]; };
const float kClusterCulledAlways = -1.0, kClusterAsObject = -2.0;  // facet_gpu.hpp
layout(location = 52) uniform uint sole_pieces;  // as the object pass's
layout(location = 53) uniform uint cluster_culling;
bool sphere_may_meet_facets(vec3 centre, float radius);
uint sole_piece_of_sphere(vec3 centre, float radius);

void main() {
  uint k = gl_GlobalInvocationID.x;
  if (k > list_entries) return;
  if (k == list_entries) {
    scan[k] = 0u;
    return;
  }
  uint r = entry_records[k];
  uvec4 entry_record = record(r);  // (first_index, triangles, object, material)
  uint state = object_state[entry_record.z];
  if (state != kCulled && cluster_culling != 0u) {
    vec4 sphere = cluster_spheres[r];
    if (sphere.w == kClusterCulledAlways) {
      state = kCulled;
    } else if (sphere.w >= 0.0 && state == kNoPiece) {
      // A sphere inside one piece meets a facet: the walk is needed only without one.
      if (sole_pieces != 0u) state = sole_piece_of_sphere(sphere.xyz, sphere.w);
      if (state == kNoPiece && !sphere_may_meet_facets(sphere.xyz, sphere.w)) state = kCulled;
    }
  }
  entry_state[k] = state;
  scan[k] = state != kCulled ? entry_record.y : 0u;
  if (state != kCulled && state != kNoPiece) atomicAdd(list_triangles_sole_piece, entry_record.y);
}

#else  // WRITE_PASS
layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 22) writeonly buffer ListOut { uvec4 list_out[]; };
layout(std430, binding = 13) writeonly buffer MaterialRanges { uvec2 material_ranges[]; };
layout(std430, binding = 27) readonly buffer MaterialFirstEntries { uint material_first_entry[]; };
// The indirect arguments (kListArgs* in replication_common.hpp): the cull pass's dispatch (one
// invocation per triangle and one more), the per-triangle dispatch (scatter, replicate.comp),
// each in rows of kRowGroups work groups,
// facets-gs' pass-1 draw, then a patch draw per material for the tessellator form.
layout(std430, binding = 25) writeonly buffer ListArgs { uint list_args[]; };
layout(std430, binding = 29) readonly buffer EntryStates { uint entry_state[]; };
layout(location = 43) uniform uint material_count;
layout(location = 51) uniform uint patch_instances;  // the tessellator form's instances per draw
const uint kTableBlockTriangles = 64u;  // kListBlockTriangles
const uint kLocalSize = 64u;  // count.comp, scatter.comp and replicate.comp
// Their dispatches come in rows of this many work groups (kListArgsRowGroups), as a dispatch may
// hold 65535 groups a dimension: a list of over 4.2 million triangles takes more than one row.
const uint kRowGroups = 1024u;

void set_block_entry(uint block, uint entry) {
  list_out[list_entries + 1u + block / 4u][block % 4u] = entry;
}

// The last entry whose first triangle is at most t (the entries' first triangles ascend).
uint last_entry_from(uint t) {
  uint lo = 0u, hi = list_entries - 1u;
  while (lo < hi) {
    uint mid = (lo + hi + 1u) / 2u;
    if (scan[mid] <= t) lo = mid; else hi = mid - 1u;
  }
  return lo;
}

void main() {
  uint k = gl_GlobalInvocationID.x;
  uint total = scan[list_entries];
  if (k < list_entries) {
    uint state = entry_state[k];
    list_out[k] = uvec4(entry_records[k], scan[k], state == kCulled ? kNoPiece : state, 0u);
  }
  uint blocks = (total + kTableBlockTriangles - 1u) / kTableBlockTriangles;
  if (k < blocks) set_block_entry(k, last_entry_from(k * kTableBlockTriangles));
  if (k == blocks) set_block_entry(k, list_entries - 1u);
  if (k < material_count) {
    uint begin = scan[material_first_entry[k]], end = scan[material_first_entry[k + 1u]];
    material_ranges[k] = uvec2(begin, end);
    uint at = 16u + 4u * k;
    list_args[at] = end - begin;
    list_args[at + 1u] = patch_instances;
    list_args[at + 2u] = begin;
    list_args[at + 3u] = 0u;
  }
  if (k != 0u) return;
  list_out[list_entries] = uvec4(total, list_triangles_sole_piece, 0u, 0u);
  list_triangles = total;
  uint cull_groups = total / kLocalSize + 1u, triangle_groups = (total + kLocalSize - 1u) / kLocalSize;
  uint args[16] = uint[16](min(cull_groups, kRowGroups), (cull_groups + kRowGroups - 1u) / kRowGroups,
                           1u, 0u, min(triangle_groups, kRowGroups),
                           (triangle_groups + kRowGroups - 1u) / kRowGroups, 1u, 0u, total, 1u, 0u,
                           0u, 0u, 0u, 0u, 0u);
  for (uint a = 0u; a < 16u; ++a) list_args[a] = args[a];
}
#endif
#endif
