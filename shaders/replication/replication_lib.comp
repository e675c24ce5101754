// Functions and buffers shared by every replication stage: the scene's triangles in the eye
// frame, the facets' matrices and clip planes, and the coverage test (a port of
// projection/coverage.hpp CoverageIndex::query). Not a program of its own: pipelines link it as
// a second shader object into each stage that declares these functions (compute, vertex,
// geometry). It is validated as a compute shader, so it uses nothing stage-specific.
// Bindings: driver/include/facet/driver/facet_gpu.hpp.

// Read-only tables are buffer textures (texelFetch reads a texel for every SIMD lane at once on
// llvmpipe, where a shader storage load takes one lane at a time), except the scene's indices
// (see GpuScene::bind_for_pulling). The scene (GpuScene):
layout(std430, binding = 3) readonly buffer Indices { uint indices[]; };
layout(binding = 8) uniform samplerBuffer position_texels;  // RGB32F, metres, object frame
layout(binding = 9) uniform samplerBuffer normal_texels;    // RGB32F
layout(binding = 10) uniform samplerBuffer uv_texels;       // RG32F
uint scene_index(uint i) { return indices[i]; }

// GpuRecord, 2 RGBA32UI texels: (first_index, triangle_count, object, material), (first_id, ...).
layout(binding = 13) uniform usamplerBuffer record_texels;
uvec4 record(uint r) { return texelFetch(record_texels, 2 * int(r)); }

// GpuObjectFrame per object, 8 texels: the columns of T_eye_object, then of T_world_object.
layout(binding = 11) uniform samplerBuffer object_frame_texels;
// GpuFacet per piece (FacetPieces), 8 texels: the columns of clip_from_eye, then the four guarded
// clip planes (a triangle repeats its first).
layout(binding = 12) uniform samplerBuffer facet_texels;
vec4 clip_plane(uint f, int k) { return texelFetch(facet_texels, 8 * int(f) + 4 + k); }

// A node of the hierarchy (GpuCoverageNode, 7 RGBA32UI texels) and the facet order (R32UI).
layout(binding = 20) uniform usamplerBuffer node_texels;
layout(binding = 21) uniform usamplerBuffer order_texels;
struct Node {
  vec4 pyramid[4];
  vec4 cone;  // bounded nodes: unit axis, sine of the half-angle
  uint first;
  uint count;
  uint bounded;
  uint range_first;  // every facet below: facet_order over [range_first, range_first + range_count)
  uint range_count;
};
Node node_at(uint i) {
  int at = 7 * int(i);
  Node node;
  for (int k = 0; k < 4; ++k) node.pyramid[k] = uintBitsToFloat(texelFetch(node_texels, at + k));
  node.cone = uintBitsToFloat(texelFetch(node_texels, at + 4));
  uvec4 leaf = texelFetch(node_texels, at + 5);  // first, count, bounded
  node.first = leaf.x;
  node.count = leaf.y;
  node.bounded = leaf.z;
  uvec4 range = texelFetch(node_texels, at + 6);
  node.range_first = range.x;
  node.range_count = range.y;
  return node;
}
uint facet_order(uint i) { return texelFetch(order_texels, int(i)).x; }

// The frame's triangle list (ListEntry in replication_common.hpp), an RGBA32UI texel per record
// in material order: (record, list position of its first triangle, the one piece all its
// triangles take or kNone, padding). The entry of a record whose object is culled holds no
// triangles: its first triangle is the next entry's.
layout(binding = 14) uniform usamplerBuffer list_texels;
uvec4 list_entry(uint e) { return texelFetch(list_texels, int(e)); }

layout(location = 40) uniform uint list_entries;   // entries in the list: every record
layout(location = 41) uniform uint cull_back_faces;  // 1: front is counter-clockwise from the eye

// Rounding slack of the coverage test, radians: every plane is moved outwards by this angle so
// that float rounding never loses a facet the double-precision reference finds.
const float kCoverageSlack = 2e-6;
const uint kNone = 0xffffffffu;
const uint kCoverageLeafSize = 4u;  // CoverageIndex's leaf size, checked by pack_coverage_nodes

// After the list_entries entries, the list's header: (its triangles, those of entries with a sole
// piece, 0, 0). Then its block table: entry k of the table, packed four to a texel, is the entry
// holding list triangle kListBlockTriangles·k; one more ends it with the last entry
// (list_block_table, or list_build.comp). A lookup then searches only the entries of one block.
const uint kListBlockTriangles = 64u;
uint list_triangle_count() { return texelFetch(list_texels, int(list_entries)).x; }
uint list_block_entry(uint block) {
  return texelFetch(list_texels, int(list_entries + 1u + block / 4u))[block % 4u];
}

// The list entry holding list triangle t (binary search on first_triangle within its block).
uint entry_of_triangle(uint t) {
  uint block = t / kListBlockTriangles;
  uint lo = list_block_entry(block), hi = list_block_entry(block + 1u);
  while (lo < hi) {
    uint mid = (lo + hi + 1u) / 2u;
    if (list_entry(mid).y <= t) lo = mid; else hi = mid - 1u;
  }
  return lo;
}

// Record r's vertex for its i-th index, its object and the ID of its first triangle.
uint record_vertex(uint r, uint i) { return scene_index(record(r).x + i); }
uint record_object(uint r) { return record(r).z; }
uint record_first_id(uint r) { return texelFetch(record_texels, 2 * int(r) + 1).x; }

// Index (into the scene's indices) of the first corner of list triangle t in entry e.
uint vertex_index_of(uint e, uint t) {
  uvec4 entry = list_entry(e);
  return record(entry.x).x + 3u * (t - entry.y);
}

// Scene vertex index of corner c (0..2) of list triangle t in entry e.
uint vertex_of(uint e, uint t, uint c) { return scene_index(vertex_index_of(e, t) + c); }

uint triangle_id(uint e, uint t) {
  uvec4 entry = list_entry(e);
  return record_first_id(entry.x) + (t - entry.y);
}

uint object_of(uint e) { return record(list_entry(e).x).z; }
uint material_of(uint e) { return record(list_entry(e).x).w; }

vec3 eye_position(uint object, uint v) {
  int at = 8 * int(object);
  mat4 T_eye_object = mat4(texelFetch(object_frame_texels, at),
                           texelFetch(object_frame_texels, at + 1),
                           texelFetch(object_frame_texels, at + 2),
                           texelFetch(object_frame_texels, at + 3));
  precise vec4 p = T_eye_object * vec4(texelFetch(position_texels, int(v)).xyz, 1.0);
  return p.xyz;
}

vec3 world_position(uint object, uint v) {
  int at = 8 * int(object) + 4;
  mat4 T_world_object = mat4(texelFetch(object_frame_texels, at),
                             texelFetch(object_frame_texels, at + 1),
                             texelFetch(object_frame_texels, at + 2),
                             texelFetch(object_frame_texels, at + 3));
  return (T_world_object * vec4(texelFetch(position_texels, int(v)).xyz, 1.0)).xyz;
}

vec3 world_normal(uint object, uint v) {
  int at = 8 * int(object) + 4;
  mat3 R_world_object = mat3(texelFetch(object_frame_texels, at).xyz,
                             texelFetch(object_frame_texels, at + 1).xyz,
                             texelFetch(object_frame_texels, at + 2).xyz);
  return R_world_object * texelFetch(normal_texels, int(v)).xyz;
}

vec2 vertex_uv(uint v) { return texelFetch(uv_texels, int(v)).xy; }

// GL clip coordinates of an eye-frame point in piece f, and its four clip distances.
vec4 facet_clip(uint f, vec3 p_eye) {
  int at = 8 * int(f);
  mat4 clip_from_eye = mat4(texelFetch(facet_texels, at), texelFetch(facet_texels, at + 1),
                            texelFetch(facet_texels, at + 2), texelFetch(facet_texels, at + 3));
  precise vec4 clip = clip_from_eye * vec4(p_eye, 1.0);
  return clip;
}
float facet_clip_distance(uint f, int k, vec3 p_eye) {
  precise float d = dot(clip_plane(f, k).xyz, p_eye);
  return d;
}

// The three eye-frame corners of list triangle t; returns its list entry.
uint triangle_eye(uint t, out vec3 p[3]) {
  uint e = entry_of_triangle(t);
  uint object = object_of(e), first = vertex_index_of(e, t);
  for (uint c = 0u; c < 3u; ++c) p[c] = eye_position(object, scene_index(first + c));
  return e;
}

// What the triangle's corners alone say of meets_cone: kCornersMiss when one plane has every
// corner outside it (the triangle misses the cone), kCornersMeet when a corner is inside every
// plane, else kCornersUndecided. Most tests end here.
const int kCornersMiss = 0, kCornersMeet = 1, kCornersUndecided = 2;
int cone_corner_test(vec3 u[3], vec4 planes[4], int plane_count) {
  bool corner_inside[3] = bool[3](true, true, true);
  for (int k = 0; k < 4; ++k) {
    if (k >= plane_count) break;
    vec3 n = planes[k].xyz;
    bool any_inside = false;
    for (int c = 0; c < 3; ++c) {
      bool inside = dot(n, u[c]) + kCoverageSlack >= 0.0;
      any_inside = any_inside || inside;
      corner_inside[c] = corner_inside[c] && inside;
    }
    if (!any_inside) return kCornersMiss;
  }
  return corner_inside[0] || corner_inside[1] || corner_inside[2] ? kCornersMeet
                                                                 : kCornersUndecided;
}

// True when the triangle with unit corner directions u meets the cone
// {X : planes[k]·X >= -slack·|X|, k < plane_count}, as triangle_meets_cone in
// projection/src/coverage.cpp. The cone over a triangle from the eye is the cone over its corner
// directions, so the flat triangle through the unit corners gives the same answer, and every
// point of it has |X| <= 1: a constant slack is at least slack·|X|, and never loses a facet.
// Where the corners leave it undecided, the flat triangle's points inside every plane are a
// convex polygon in the triangle's barycentric (alpha, beta), cut by three constraints of the
// triangle and one per plane; it is empty unless one of its vertices, where two constraints'
// lines cross, satisfies the others. The CPU clips the triangle instead (Sutherland–Hodgman),
// which made the walk seven times slower on llvmpipe (driver/README.md): the polygon's arrays,
// indexed by how many vertices each lane has kept, are loaded and stored one lane at a time. The
// crossings' loops
// have constant trip counts (18 pairs, 7 constraints), and llvmpipe ends an invocation's loops
// after 65535 iterations shared by all of them (LP_MAX_TGSI_LOOP_ITERATIONS).
// Two of the triangle's own constraints cross at a corner, which the corner test has decided.
const ivec2 kConstraintPairs[18] = ivec2[18](
    ivec2(0, 3), ivec2(0, 4), ivec2(0, 5), ivec2(0, 6), ivec2(1, 3), ivec2(1, 4), ivec2(1, 5),
    ivec2(1, 6), ivec2(2, 3), ivec2(2, 4), ivec2(2, 5), ivec2(2, 6), ivec2(3, 4), ivec2(3, 5),
    ivec2(3, 6), ivec2(4, 5), ivec2(4, 6), ivec2(5, 6));
bool meets_cone(vec3 u[3], vec4 planes[4], int plane_count) {
  int corners = cone_corner_test(u, planes, plane_count);
  if (corners != kCornersUndecided) return corners == kCornersMeet;
  // The point u0 + alpha (u1 - u0) + beta (u2 - u0) is inside constraint c where
  // c.x alpha + c.y beta + c.z >= 0: alpha >= 0, beta >= 0, alpha + beta <= 1, then the planes
  // (an unused plane's constraint always holds).
  vec3 e1 = u[1] - u[0], e2 = u[2] - u[0];
  vec3 c[7];
  c[0] = vec3(1.0, 0.0, 0.0);
  c[1] = vec3(0.0, 1.0, 0.0);
  c[2] = vec3(-1.0, -1.0, 1.0);
  for (int k = 0; k < 4; ++k) {
    vec3 n = planes[k].xyz;
    c[3 + k] = k < plane_count ? vec3(dot(n, e1), dot(n, e2), dot(n, u[0]) + kCoverageSlack)
                               : vec3(0.0, 0.0, 1.0);
  }
  // A crossing is tested against the other five constraints (its own two hold there up to
  // rounding), with room for rounding only: the slack above is what keeps it conservative.
  bool meets = false;
  for (int p = 0; p < 18; ++p) {
    ivec2 pair = kConstraintPairs[p];
    vec3 a = c[pair.x], b = c[pair.y];
    float det = a.x * b.y - a.y * b.x;
    vec3 vertex = vec3((b.z * a.y - a.z * b.y) / det, (a.z * b.x - b.z * a.x) / det, 1.0);
    bool inside = abs(det) >= 1e-12;
    for (int k = 0; k < 7; ++k)
      inside = inside && (k == pair.x || k == pair.y || dot(c[k], vertex) >= -1e-7);
    meets = meets || inside;
  }
  return meets;
}

// Whether the cone (unit axis, sine of its half-angle) lies inside the triangle's cone, given the
// inward unit normals of the triangle's edge planes, with room to spare for float rounding: then
// every facet below meets the triangle.
bool cone_inside(vec3 e[3], vec4 cone) {
  const float kInsideMargin = 1e-5;
  for (int k = 0; k < 3; ++k) {
    if (dot(e[k], cone.xyz) < cone.w + kInsideMargin) return false;
  }
  return true;
}

// False for triangles that are culled before any facet test: non-finite corners, degenerate or
// edge-on triangles, and back faces when culling is on (as in CoverageIndex::query).
bool triangle_may_cover(vec3 p[3]) {
  for (int c = 0; c < 3; ++c) {
    if (any(isnan(p[c])) || any(isinf(p[c]))) return false;
  }
  vec3 normal = cross(p[1] - p[0], p[2] - p[0]);
  float facing = dot(normal, p[0]);
  if (cull_back_faces != 0u && !(facing < 0.0)) return false;
  // A triangle whose plane passes through the eye is seen edge-on and covers no pixel; the
  // reference agrees (up to its rounding), but the slack below would list every facet it grazes.
  float scale = max(length(p[0]), max(length(p[1]), length(p[2])));
  return abs(facing) > 1e-6 * length(normal) * scale;
}

// The coverage grid (pack_coverage_grid): one R32UI buffer texture.
layout(binding = 15) uniform usamplerBuffer grid_texels;
uint grid_word(uint i) { return texelFetch(grid_texels, int(i)).x; }
// The same words four to a texel, for the per-piece records that start on one (bucket ranges,
// pyramid corners): one fetch instead of four.
layout(binding = 19) uniform usamplerBuffer grid_vec4_texels;
uvec4 grid_vec4(uint i) { return texelFetch(grid_vec4_texels, int(i / 4u)); }
// The piece that draws facet f (FacetPieces::piece_of_facet, from the grid's header word 22).
uint piece_of_facet(uint f) { return grid_word(grid_word(22) + f); }

// Walks the facets that triangle p may cover, in the hierarchy's fixed order, and returns how
// many there are. When pair_base != kNone, hands the k-th facet's piece to
// write_pair(pair_base + k, t, piece), which the calling stage defines. When wanted != kNone, stops at the
// wanted-th facet and returns its piece in wanted_facet (kNone when there are fewer). A quad's two
// facets both write it, and pass 3 draws it twice with the same depths.
void write_pair(uint at, uint t, uint facet);
uint walk_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet) {
  wanted_facet = kNone;
  if (!triangle_may_cover(p)) return 0u;
  vec3 u[3] = vec3[3](normalize(p[0]), normalize(p[1]), normalize(p[2]));
  // Inward unit normals of the triangle's own cone. A node whose cone lies inside it holds only
  // facets the triangle covers: they are taken as a range, without a test each, which keeps the
  // walk short (and within llvmpipe's loop budget) for triangles that cover many facets.
  float orientation = dot(cross(u[0], u[1]), u[2]) >= 0.0 ? 1.0 : -1.0;
  vec3 e[3];
  for (int k = 0; k < 3; ++k) {
    vec3 normal = orientation * cross(u[k], u[k < 2 ? k + 1 : 0]);
    float len = length(normal);
    e[k] = len > 0.0 ? normal / len : vec3(0.0);
  }
  uint found = 0u;
  uint stack[64];
  int top = 0;
  stack[top++] = 0u;
  while (top > 0) {
    Node node = node_at(stack[--top]);
    if (node.bounded != 0u && !meets_cone(u, node.pyramid, 4)) continue;
    if (node.bounded != 0u && cone_inside(e, node.cone)) {
      if (wanted != kNone && wanted < found + node.range_count) {
        wanted_facet = piece_of_facet(facet_order(node.range_first + (wanted - found)));
        return wanted + 1u;
      }
      if (pair_base != kNone) {
        // Eight pairs per iteration: a fraction of the loop budget per facet.
        for (uint k = 0u; k < node.range_count; k += 8u) {
          for (uint m = 0u; m < 8u; ++m) {
            if (k + m < node.range_count)
              write_pair(pair_base + found + k + m, t,
                         piece_of_facet(facet_order(node.range_first + k + m)));
          }
        }
      }
      found += node.range_count;
      continue;
    }
    if (node.count > 0u) {
      // A leaf holds at most kCoverageLeafSize facets (GpuCoverageNode).
      for (uint m = 0u; m < kCoverageLeafSize; ++m) {
        if (m >= node.count) break;
        uint f = facet_order(node.first + m);
        vec4 planes[4] = vec4[4](clip_plane(f, 0), clip_plane(f, 1), clip_plane(f, 2), vec4(0.0));
        if (!meets_cone(u, planes, 3)) continue;
        if (found == wanted) {
          wanted_facet = piece_of_facet(f);
          return found + 1u;
        }
        if (pair_base != kNone) write_pair(pair_base + found, t, piece_of_facet(f));
        ++found;
      }
    } else if (top + 2 <= 64) {
      // Second child pushed last is visited first, as in CoverageIndex::query.
      stack[top++] = node.first;
      stack[top++] = node.first + 1u;
    }
  }
  return found;
}

// Whether a sphere (eye frame: centre in metres, radius) may meet any facet's guarded pyramid,
// for object culling on the GPU (list_build.comp): sphere_may_meet_facets (facet_gpu.hpp) with the
// nodes' bounding pyramids in place of their cones. A sphere wholly outside one plane through the
// eye misses that pyramid, so the answer is never false for a sphere that meets a facet. Needs a
// hierarchy with at least one facet.
bool sphere_may_meet_facets(vec3 centre, float radius) {
  if (length(centre) <= radius) return true;  // the eye is inside: every direction
  uint stack[64];
  int top = 0;
  stack[top++] = 0u;
  while (top > 0) {
    Node node = node_at(stack[--top]);
    if (node.bounded != 0u) {
      bool outside = false;
      for (int k = 0; k < 4; ++k) outside = outside || dot(node.pyramid[k].xyz, centre) < -radius;
      if (outside) continue;
    }
    if (node.count > 0u) {
      for (uint m = 0u; m < kCoverageLeafSize; ++m) {
        if (m >= node.count) break;
        uint f = facet_order(node.first + m);
        bool outside = false;
        for (int k = 0; k < 3; ++k) outside = outside || dot(clip_plane(f, k).xyz, centre) < -radius;
        if (!outside) return true;
      }
    } else if (top + 2 <= 64) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1u;
    }
  }
  return false;
}

// ---- Coverage grid (projection/coverage_grid.hpp, CoverageGrid: the same arithmetic in float,
// with the padding float rounding needs) ----
layout(location = 44) uniform uint coverage_by_grid;  // 0: the hierarchy walk for every triangle

const uint kChartCylindrical = 0u, kChartEquirectangular = 1u, kChartFisheye = 2u,
           kChartPerspective = 3u;                      // CoverageChart
const uint kGridMaxBuckets = 256u;                      // CoverageGrid::kMaxBuckets
const uint kGridMaxCandidates = 512u;                   // CoverageGrid::kMaxCandidates
const float kPi = 3.14159265358979;
const float kGnomonicMinDepth = 0.05;  // CoverageGrid::kGnomonicMinDepth
const float kGnomonicPad = 1e-5;       // CoverageGrid::kGnomonicPad
const float kPoleMargin = 1e-3;
const float kShortArc = 1e-2;

float grid_float(uint i) { return uintBitsToFloat(grid_word(i)); }

// The grid's chart, whether it is periodic, and whether its buckets are cells. A program built
// for one kind of grid (GRID_CHART, GRID_PERIODIC and GRID_CELL_BUCKETS defined: `facets`' grid
// pass) has them as constants, so that the compiler drops the other kinds' code, which llvmpipe
// would otherwise run for every triangle with its lanes masked.
uint grid_chart() {
#ifdef GRID_CHART
  return uint(GRID_CHART);
#else
  return grid_word(0);
#endif
}
bool grid_periodic() {
#ifdef GRID_PERIODIC
  return GRID_PERIODIC != 0;
#else
  return grid_word(1) != 0u;
#endif
}
bool grid_cell_buckets() {
#ifdef GRID_CELL_BUCKETS
  return GRID_CELL_BUCKETS != 0;
#else
  return grid_word(23) != 0u;
#endif
}

float wrap_pi(float angle) { return angle - 2.0 * kPi * round(angle / (2.0 * kPi)); }

// The (θ, φ) box of the spherical triangle with unit base-frame corners b: x = θ_lo, y = θ_hi,
// z = φ_lo, w = φ_hi; full_phi: every azimuth; false when the walk must take the triangle.
bool direction_box(vec3 b[3], uint chart, out vec4 box, out bool full_phi) {
  bool is_polar = chart <= kChartEquirectangular;
  vec3 A = is_polar ? vec3(0, 1, 0) : vec3(0, 0, -1);
  vec3 e1 = is_polar ? vec3(0, 0, -1) : vec3(1, 0, 0);
  vec3 e2 = is_polar ? vec3(1, 0, 0) : vec3(0, 1, 0);
  float theta[3], phi[3], sin_theta[3];
  for (int c = 0; c < 3; ++c) {
    sin_theta[c] = length(cross(b[c], A));
    theta[c] = atan(sin_theta[c], dot(b[c], A));
    phi[c] = atan(dot(b[c], e2), dot(b[c], e1));
  }
  const float vertex_pad = 4e-6;
  float lo = min(theta[0], min(theta[1], theta[2])) - vertex_pad;
  float hi = max(theta[0], max(theta[1], theta[2])) + vertex_pad;
  full_phi = false;
  box = vec4(0.0);
  for (int i = 0; i < 3; ++i) {
    int j = i < 2 ? i + 1 : 0;
    vec3 n = cross(b[i], b[j]);
    float len = length(n);
    if (len < kShortArc) {
      if (dot(b[i], b[j]) < 0.0) return false;
      float chord = length(b[i] - b[j]);
      lo = min(lo, min(theta[i], theta[j]) - chord - vertex_pad);
      hi = max(hi, max(theta[i], theta[j]) + chord + vertex_pad);
      continue;
    }
    n /= len;
    float an = dot(A, n);
    vec3 p = A - an * n;
    float circle_min = atan(abs(an), length(cross(A, n)));
    float arc_pad = 2e-6 / len + vertex_pad;
    const float on = -1e-5;
    if (dot(cross(b[i], p), n) >= on && dot(cross(p, b[j]), n) >= on)
      lo = min(lo, circle_min - arc_pad);
    if (dot(cross(b[i], -p), n) >= on && dot(cross(-p, b[j]), n) >= on)
      hi = max(hi, kPi - circle_min + arc_pad);
  }
  float d01 = wrap_pi(phi[1] - phi[0]), d12 = wrap_pi(phi[2] - phi[1]),
        d20 = wrap_pi(phi[0] - phi[2]);
  float winding = d01 + d12 + d20;
  if (!(abs(winding) < 0.5 || abs(abs(winding) - 2.0 * kPi) < 0.5)) return false;
  if (abs(winding) > kPi) {
    vec3 normal = cross(b[1] - b[0], b[2] - b[0]);
    if (dot(A, normal) * dot(normal, b[0]) > 0.0) lo = 0.0; else hi = kPi;
    full_phi = true;
  }
  if (lo < kPoleMargin) {
    lo = 0.0;
    full_phi = true;
  }
  if (hi > kPi - kPoleMargin) {
    hi = kPi;
    full_phi = true;
  }
  box.x = lo;
  box.y = hi;
  if (!full_phi) {
    float c1 = d01, c2 = d01 + d12;
    float min_sin = min(sin_theta[0], min(sin_theta[1], sin_theta[2]));
    float phi_pad = 2e-6 / max(min_sin, 1e-9) + 4e-6;
    box.z = phi[0] + min(0.0, min(c1, c2)) - phi_pad;
    box.w = phi[0] + max(0.0, max(c1, c2)) + phi_pad;
    if (box.w - box.z >= 2.0 * kPi) full_phi = true;
  }
  if (full_phi) box.zw = vec2(-kPi, kPi);
  return true;
}

// The chart box (p_lo, p_hi, q_lo, q_hi) of a direction box; false when nothing can be seen.
bool chart_box(uint chart, vec4 d, bool full_phi, out vec4 box) {
  box = vec4(0.0);
  if (chart <= kChartEquirectangular) {
    if (chart == kChartEquirectangular) {
      box.zw = vec2(kPi / 2.0 - d.y, kPi / 2.0 - d.x);
    } else {
      box.z = cos(d.y) / max(sin(d.y), 1e-6);
      box.w = cos(d.x) / max(sin(d.x), 1e-6);
    }
    box.xy = d.zw;
    return true;
  }
  float rho_lo = d.x, rho_hi = d.y;
  if (chart == kChartPerspective) {
    if (d.x >= kPi / 2.0) return false;
    float cap = grid_float(8u);
    rho_lo = tan(d.x);
    rho_hi = d.y >= kPi / 2.0 - 1e-6 ? cap : min(tan(d.y), cap);
  }
  if (full_phi) {
    box = vec4(-rho_hi, rho_hi, -rho_hi, rho_hi);
    return true;
  }
  vec2 lo = vec2(1e30), hi = vec2(-1e30);
  for (int k = 0; k < 2; ++k) {
    float phi = k == 0 ? d.z : d.w;
    vec2 dir = vec2(cos(phi), sin(phi));
    lo = min(lo, min(rho_lo * dir, rho_hi * dir));
    hi = max(hi, max(rho_lo * dir, rho_hi * dir));
  }
  for (int k = 0; k < 4; ++k) {
    float offset = mod(float(k) * kPi / 2.0 - d.z, 2.0 * kPi);
    if (d.z + offset <= d.w) {
      vec2 axis = k == 0 ? vec2(1, 0) : k == 1 ? vec2(0, 1) : k == 2 ? vec2(-1, 0) : vec2(0, -1);
      lo = min(lo, rho_hi * axis);
      hi = max(hi, rho_hi * axis);
    }
  }
  box = vec4(lo.x, hi.x, lo.y, hi.y);
  return true;
}

// Cells meeting [lo, hi] among `cells` cells between ascending float breaks from grid word `at`:
// the first and last; false when none (CoverageGrid's cells_between).
bool cells_between(uint at, uint cells, float lo, float hi, out uint first, out uint last) {
  first = 0u;
  last = 0u;
  if (hi < grid_float(at) || lo > grid_float(at + cells)) return false;
  // Lower bound of lo and upper bound of hi among the cells + 1 breaks.
  uint a = 0u, b = cells + 1u;
  while (a < b) {
    uint middle = (a + b) / 2u;
    if (grid_float(at + middle) < lo) a = middle + 1u; else b = middle;
  }
  uint c = 0u, d = cells + 1u;
  while (c < d) {
    uint middle = (c + d) / 2u;
    if (grid_float(at + middle) <= hi) c = middle + 1u; else d = middle;
  }
  first = uint(clamp(int(a) - 1, 0, int(cells) - 1));
  last = uint(clamp(int(c) - 1, 0, int(cells) - 1));
  return true;
}

// The buckets a chart box touches: (first column, first row, columns, rows); false when none.
bool bucket_range(vec4 box, bool full_p, out uvec4 range) {
  range = uvec4(0u);
  uint columns = grid_word(2), rows = grid_word(3);
  if (grid_cell_buckets()) {
    // Cell buckets (CoverageGrid::buckets): the box grown by the pads, against the breaks.
    uint pads = grid_word(23), p_at = grid_word(23) + 2u, q_at = p_at + columns + 1u;
    float pad_p = grid_float(pads), pad_q = grid_float(pads + 1u);
    uint first_row, last_row;
    if (!cells_between(q_at, rows, box.z - pad_q, box.w + pad_q, first_row, last_row)) return false;
    range.y = first_row;
    range.w = last_row - first_row + 1u;
    float width = box.y - box.x + 2.0 * pad_p;
    bool periodic = grid_periodic();
    if (periodic && (full_p || width >= 2.0 * kPi)) {
      range.z = columns;
      return true;
    }
    float p0 = grid_float(p_at), p_end = grid_float(p_at + columns);
    float lo = box.x - pad_p;
    if (periodic) lo = p0 + mod(lo - p0, 2.0 * kPi);
    float hi = lo + width;
    uint first, last;
    if (!periodic) {
      if (!cells_between(p_at, columns, lo, hi, first, last)) return false;
      range.x = first;
      range.z = last - first + 1u;
      return true;
    }
    uint unused;
    cells_between(p_at, columns, lo, lo, first, unused);
    cells_between(p_at, columns, min(hi, p_end), min(hi, p_end), unused, last);
    if (hi > p_end) cells_between(p_at, columns, hi - 2.0 * kPi, hi - 2.0 * kPi, unused, last);
    if (hi > p_end) last += columns;
    range.x = first;
    range.z = min(last - first + 1u, columns);
    if (range.z == columns) range.x = 0u;
    return true;
  }
  float p0 = grid_float(4u), q0 = grid_float(5u), dp = grid_float(6u), dq = grid_float(7u);
  float j_lo = max(clamp(floor((box.z - q0) / dq), -1.0, float(rows)), 0.0);
  float j_hi = min(clamp(floor((box.w - q0) / dq), -1.0, float(rows)), float(rows) - 1.0);
  if (j_hi < j_lo) return false;
  range.y = uint(j_lo);
  range.w = uint(j_hi - j_lo) + 1u;
  if (grid_periodic()) {
    range.z = columns;
    if (full_p) return true;
    float i_lo = floor((box.x - p0) / dp), i_hi = floor((box.y - p0) / dp);
    if (i_hi - i_lo + 1.0 >= float(columns)) return true;
    float first = i_lo - float(columns) * floor(i_lo / float(columns));
    range.x = min(uint(first), columns - 1u);
    range.z = uint(i_hi - i_lo) + 1u;
    return true;
  }
  float i_lo = max(clamp(floor((box.x - p0) / dp), -1.0, float(columns)), 0.0);
  float i_hi = min(clamp(floor((box.y - p0) / dp), -1.0, float(columns)), float(columns) - 1.0);
  if (i_hi < i_lo) return false;
  range.x = uint(i_lo);
  range.z = uint(i_hi - i_lo) + 1u;
  return true;
}

// The one piece whose guarded pyramid holds a sphere (eye frame: centre in metres, radius) while
// no other piece's may meet it, else kNone: sole_piece_of_sphere (facet_gpu.hpp) in float, for
// the GPU's triangle list. Only for cell buckets whose pads are under a cell (the caller knows);
// the pieces of the cells within two of those about the centre are tested. A sphere is inside a
// plane only by 1e-6 of its distance beyond its radius, more than float rounding (about 3e-7 of
// it), and meets another piece unless it lies that far beyond its radius outside one of its
// planes' (the radius is grown by the caller), so float never claims a sole piece that double
// precision would not. Near boxes of more than 4 cells a side answer kNone at once.
uint sole_piece_of_sphere(vec3 centre, float radius) {
  float distance = length(centre);
  if (!(distance > radius)) return kNone;
  mat3 R_base_eye = mat3(grid_float(12u), grid_float(13u), grid_float(14u), grid_float(15u),
                         grid_float(16u), grid_float(17u), grid_float(18u), grid_float(19u),
                         grid_float(20u));
  vec3 b = R_base_eye * (centre / distance);
  vec3 corners[3] = vec3[3](b, b, b);
  uint chart = grid_chart();
  vec4 angles, box;
  bool full_phi = false;
  if (!direction_box(corners, chart, angles, full_phi)) return kNone;
  if (!chart_box(chart, angles, full_phi, box)) return kNone;
  uvec4 near;
  if (!bucket_range(box, full_phi && chart <= kChartEquirectangular, near)) return kNone;
  if (near.z > 4u || near.w > 4u) return kNone;
  uint columns = grid_word(2), rows = grid_word(3);
  bool periodic = grid_periodic();
  if (periodic && near.z + 4u > columns) return kNone;
  uint first_offset = grid_word(9), pieces_offset = grid_word(10);
  uint row_lo = near.y >= 2u ? near.y - 2u : 0u;
  uint row_hi = min(near.y + near.w + 1u, rows - 1u);
  float margin = 1e-6 * distance;
  uint sole = kNone;
  for (uint j = row_lo; j <= row_hi; ++j) {
    for (uint k = 0u; k < near.z + 4u; ++k) {
      // Column near.x + k - 2; GLSL's % is undefined for negative operands.
      uint i = near.x + k;
      if (periodic) {
        i = (i + columns - 2u) % columns;
      } else if (i < 2u || i - 2u >= columns) {
        continue;
      } else {
        i -= 2u;
      }
      uint bucket = first_offset + j * columns + i;
      for (uint m = grid_word(bucket); m < grid_word(bucket + 1u); ++m) {
        uint p = grid_word(pieces_offset + m);
        if (p == sole) continue;
        bool may_meet_piece = true, inside = true;
        for (int n = 0; n < 4; ++n) {
          float d = dot(clip_plane(p, n).xyz, centre);
          may_meet_piece = may_meet_piece && !(d < -radius - margin);
          inside = inside && d >= radius + margin;
        }
        if (!may_meet_piece) continue;
        if (sole != kNone || !inside) return kNone;
        sole = p;
      }
    }
  }
  return sole;
}

// Whether candidate piece f and the triangle with unit corners u may meet: false when one of the
// piece's four guarded planes or one of the triangle's three edge planes (edge[k], with their
// rounding slack in w) has all corners of the other outside it. Either is a separating plane of
// the two cones (the triangle's cone is where its edge planes meet, the piece's the conic hull of
// its pyramid corners, both within a hemisphere), so nothing that meets is rejected. The test is
// exact where the two lie in a common open hemisphere: there both are convex polygons in the
// gnomonic chart, and edge normals separate disjoint convex polygons. Elsewhere (a triangle
// spanning more than a right angle seen from the eye, and pieces near its edges) it may keep a
// piece that the triangle misses, which pass 3 clips to nothing. Without the clipping of
// meets_cone, which made the cylinder's frame 30% slower.
bool may_meet(vec3 u[3], vec4 edge[3], uint f) {
  for (int k = 0; k < 4; ++k) {
    vec3 n = clip_plane(f, k).xyz;
    if (dot(n, u[0]) + kCoverageSlack < 0.0 && dot(n, u[1]) + kCoverageSlack < 0.0 &&
        dot(n, u[2]) + kCoverageSlack < 0.0)
      return false;
  }
  uint at = grid_word(21) + 12u * f;
  vec4 w0 = uintBitsToFloat(grid_vec4(at)), w1 = uintBitsToFloat(grid_vec4(at + 4u)),
       w2 = uintBitsToFloat(grid_vec4(at + 8u));
  vec3 c[4] = vec3[4](w0.xyz, vec3(w0.w, w1.xy), vec3(w1.zw, w2.x), w2.yzw);
  for (int k = 0; k < 3; ++k) {
    if (dot(edge[k].xyz, c[0]) + edge[k].w < 0.0 && dot(edge[k].xyz, c[1]) + edge[k].w < 0.0 &&
        dot(edge[k].xyz, c[2]) + edge[k].w < 0.0 && dot(edge[k].xyz, c[3]) + edge[k].w < 0.0)
      return false;
  }
  return true;
}

// What the grid makes of a triangle (grid_query).
const uint kGridEmpty = 0u;  // it covers nothing
const uint kGridLane = 1u;   // one invocation tests its candidates (grid_coverage)
const uint kGridWide = 2u;   // beyond one invocation's bounds, within the wide pass's
const uint kGridWalk = 3u;   // the walk takes it
// The wide pass (replication/count_wide.comp): the 64 invocations of a work group share one
// triangle's candidates, of at most kWideMaxRows bucket rows and kWideMaxCandidates listed pieces.
// llvmpipe counts a work group's loop iterations against one budget of 65535: each invocation
// visits at most the range's rows and 128 listed pieces, twice, with a binary search over a row's
// buckets (at most 4096, 12 steps) for each piece where buckets are not cells, so each of the
// group's 8 SIMD rows of 8 lanes takes at most 2·(256 + 128·13) iterations, all 8 about 31,000.
const uint kWideMaxRows = 256u;
const uint kWideMaxCandidates = 8192u;

// A triangle against the grid: its unit corners, the inward unit normals of its edge planes (with
// their rounding slack in w), the buckets its chart box touches (first column, first row,
// columns, rows) and how many pieces those buckets list.
struct GridQuery {
  vec3 u[3];
  vec4 edge[3];
  uvec4 range;
  uint listed;
};

uint grid_query(vec3 p[3], out GridQuery q) {
  q.range = uvec4(0u);
  q.listed = 0u;
  if (!triangle_may_cover(p)) return kGridEmpty;
  q.u = vec3[3](normalize(p[0]), normalize(p[1]), normalize(p[2]));
  mat3 R_base_eye = mat3(grid_float(12u), grid_float(13u), grid_float(14u), grid_float(15u),
                         grid_float(16u), grid_float(17u), grid_float(18u), grid_float(19u),
                         grid_float(20u));
  vec3 b[3] = vec3[3](R_base_eye * q.u[0], R_base_eye * q.u[1], R_base_eye * q.u[2]);
  uint chart = grid_chart();
  // A perspective chart is gnomonic: a triangle in front has its chart box at its corners
  // (CoverageGrid::gnomonic_box).
  vec4 box;
  bool full_phi = false;
  float depth = min(-b[0].z, min(-b[1].z, -b[2].z));
  if (chart == kChartPerspective && depth > kGnomonicMinDepth) {
    vec2 c0 = b[0].xy / -b[0].z, c1 = b[1].xy / -b[1].z, c2 = b[2].xy / -b[2].z;
    vec2 lo = min(c0, min(c1, c2)), hi = max(c0, max(c1, c2));
    float pad = kGnomonicPad * (1.0 + max(dot(lo, lo), dot(hi, hi)));
    box = vec4(lo.x - pad, hi.x + pad, lo.y - pad, hi.y + pad);
  } else {
    vec4 angles;
    if (!direction_box(b, chart, angles, full_phi)) return kGridWalk;
    if (!chart_box(chart, angles, full_phi, box)) return kGridEmpty;
  }
  if (!bucket_range(box, full_phi && chart <= kChartEquirectangular, q.range)) return kGridEmpty;
  uint buckets = q.range.z * q.range.w;
  if (buckets > kGridMaxBuckets && q.range.w > kWideMaxRows) return kGridWalk;
  uint columns = grid_word(2);
  uint first_offset = grid_word(9);
  // Listed pieces, row by row from at most two runs of buckets.
  uint end = q.range.x + q.range.z;
  for (uint j = q.range.y; j < q.range.y + q.range.w; ++j) {
    uint row = first_offset + j * columns;
    q.listed += grid_word(row + min(end, columns)) - grid_word(row + q.range.x);
    if (end > columns) q.listed += grid_word(row + end - columns) - grid_word(row);
  }
  // Inward unit normals of the triangle's edge planes; the slack covers the rounding of a
  // normal made from nearly parallel corners (a short edge: the test then never rejects).
  float orientation = dot(cross(q.u[0], q.u[1]), q.u[2]) >= 0.0 ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k) {
    vec3 normal = orientation * cross(q.u[k], q.u[k < 2 ? k + 1 : 0]);
    float len = length(normal);
    q.edge[k] = len > 1e-6 ? vec4(normal / len, kCoverageSlack + 4e-7 / len) : vec4(0, 0, 0, 1);
  }
  if (buckets <= kGridMaxBuckets && q.listed <= kGridMaxCandidates) return kGridLane;
  return q.range.w <= kWideMaxRows && q.listed <= kWideMaxCandidates ? kGridWide : kGridWalk;
}

// A piece is listed at most once in a bucket, so a one-bucket range needs no de-duplication, and
// cell buckets list each piece once, so they need none at all.
bool grid_single_listing(GridQuery q) {
  return q.range.z * q.range.w == 1u || grid_cell_buckets();
}

// Whether piece f, listed in bucket column i of row j of the query's range, is a candidate there:
// where pieces may be listed in several buckets, only in the first bucket, in visiting order, that
// its range and the query's share.
bool grid_first_listing(GridQuery q, uint i, uint j, uint f) {
  uint columns = grid_word(2);
  uvec4 fb = grid_vec4(grid_word(11) + 4u * f);
  uint first_row = max(q.range.y, fb.y);
  uint first_column = max(q.range.x, fb.x);
  if (grid_periodic())
    first_column = (q.range.x + columns - fb.x) % columns < fb.z ? q.range.x : fb.x;
  return i == first_column && j == first_row;
}

// walk_coverage's contract, answered from the grid into `found` when one invocation takes the
// triangle (else false): conservative like the walk, with the few extra facets may_meet keeps.
bool grid_coverage(vec3 p[3], uint t, uint pair_base, uint wanted, out uint wanted_facet,
                   out uint found, out uint status) {
  wanted_facet = kNone;
  found = 0u;
  GridQuery q;
  status = grid_query(p, q);
  if (status == kGridEmpty) return true;
  if (status != kGridLane) return false;
  uint columns = grid_word(2);
  bool periodic = grid_periodic();
  uint first_offset = grid_word(9), facets_offset = grid_word(10);
  bool single = grid_single_listing(q);
  // The loop always runs to its end (no early return at the wanted facet), so that a triangle
  // takes the same path in every pass that covers it.
  for (uint j = q.range.y; j < q.range.y + q.range.w; ++j) {
    for (uint k = 0u; k < q.range.z; ++k) {
      uint i = periodic ? (q.range.x + k) % columns : q.range.x + k;
      uint bucket = first_offset + j * columns + i;
      for (uint m = grid_word(bucket); m < grid_word(bucket + 1u); ++m) {
        uint f = grid_word(facets_offset + m);
        if (!single && !grid_first_listing(q, i, j, f)) continue;
        if (!may_meet(q.u, q.edge, f)) continue;
        if (found == wanted) wanted_facet = f;
        if (pair_base != kNone) write_pair(pair_base + found, t, f);
        ++found;
      }
    }
  }
  return true;
}

// cover()'s answer from the entry's sole piece or the grid, or kNeedsWalk when neither takes the
// triangle (then nothing it wrote counts). Pass 1 of `facets` sends those triangles to a dispatch
// of the walk of their own: llvmpipe runs both sides of every branch for all lanes of a SIMD
// group, so the walk's code inside pass 1 cost every triangle its time (cylinder 400x300: a 39 ms
// frame against 28 ms without it).
const uint kNeedsWalk = 0xfffffffeu;
uint cover_without_walk(vec3 p[3], uint t, uint e, uint pair_base, uint wanted,
                        out uint wanted_facet) {
  wanted_facet = kNone;
  if (coverage_by_grid == 0u) return kNeedsWalk;
  // An object inside one piece and clear of the others: each of its triangles takes that piece.
  uint sole = list_entry(e).z;
  if (sole != kNone) {
    if (!triangle_may_cover(p)) return 0u;
    if (wanted == 0u) wanted_facet = sole;
    if (pair_base != kNone) write_pair(pair_base, t, sole);
    return 1u;
  }
  uint found = 0u, status;
  if (grid_coverage(p, t, pair_base, wanted, wanted_facet, found, status)) return found;
  return kNeedsWalk;
}

// The facets triangle t (list entry e) with eye-frame corners p may cover: walk_coverage's
// contract, from the entry's sole piece or the grid where they take the triangle, else the walk.
// The walk has one call site: inlined at each of several, it made the whole pass 1 slower on
// llvmpipe (cylinder 400x300: 99 against 71-76 ms a frame).
uint cover(vec3 p[3], uint t, uint e, uint pair_base, uint wanted, out uint wanted_facet) {
  uint found = cover_without_walk(p, t, e, pair_base, wanted, wanted_facet);
  if (found != kNeedsWalk) return found;
  return walk_coverage(p, t, pair_base, wanted, wanted_facet);
}
