// Tessellator form of the replication (Lorenz & Döllner, the single-pass form of the extended
// paper, in GL 4.5 tessellation), control stage: one invocation per list triangle counts the
// facets the triangle covers (cover(), the same coverage as `facets` and `facets-gs`) and sets
// tessellation levels that make at least that many line segments. The table is closed form:
// isolines of `segments` pieces each, segments = ceil(count / max_level) and
// lines = ceil(count / segments), both <= max_level (GL_MAX_TESS_GEN_LEVEL). A triangle that
// covers nothing gets level 0: the tessellator drops the patch before any later stage runs.
// A patch makes at most max_level² segments; when an output has more pieces than that, the draw
// is instanced and instance i takes the triangle's replicas [i·max_level², (i+1)·max_level²).
layout(vertices = 1) out;

flat in uint v_index[];
flat in uint v_instance[];
// (list triangle, first replica of this patch, replicas of this patch, segments per line).
patch out uvec4 tc_replicas;

layout(location = 46) uniform uint max_level;  // GL_MAX_TESS_GEN_LEVEL

// Visible triangles and replicas drawn (binding::stats).
layout(std430, binding = 12) buffer Stats { uint visible_triangles; uint replicas_drawn; };

uint triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint e, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) {}

void main() {
  uint t = v_index[0];
  vec3 p[3];
  uint e = triangle_eye(t, p);
  uint unused;
  uint count = cover(p, t, e, 0xffffffffu, 0xffffffffu, unused);
  uint per_patch = max_level * max_level;
  uint first = v_instance[0] * per_patch;
  uint here = count > first ? min(count - first, per_patch) : 0u;
  if (here > 0u) {
    if (first == 0u) atomicAdd(visible_triangles, 1u);
    atomicAdd(replicas_drawn, here);
  }
  uint segments = max((here + max_level - 1u) / max_level, 1u);
  uint lines = (here + segments - 1u) / segments;
  tc_replicas = uvec4(t, first, here, segments);
  // Level 0 on a patch's first outer level discards it (early culling).
  gl_TessLevelOuter[0] = float(lines);
  gl_TessLevelOuter[1] = float(segments);
}
