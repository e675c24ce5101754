// Per-vertex projection baseline, tessellation control: one patch per scene triangle. Culls back
// faces once for the whole (flat) patch and chooses how finely to cut each edge so that the
// straight projected pieces stay close to the exact curved image.
//
// A projected edge from q_a to q_b bends away from its chord by d = |P(midpoint) - (q_a + q_b)/2|
// output pixels. Cut into n equal pieces, a smooth curve's chord error falls as d / n², so
// n = ceil(sqrt(d / tolerance_px)), capped at max_level. An edge or the centre where P has no
// value takes max_level, so that the geometry stage drops small pieces rather than the whole
// triangle. The level of an edge depends only on its two end points, so the two triangles that
// share it cut it alike (no cracks).
layout(vertices = 3) out;

in vec3 g_p_eye[];
in vec3 g_n_world[];
in vec2 g_uv[];
in vec3 g_p_world[];
in vec3 g_barycentric[];
flat in uint g_triangle_id[];

out vec3 tc_p_eye[];
out vec3 tc_n_world[];
out vec2 tc_uv[];
out vec3 tc_p_world[];
out vec3 tc_barycentric[];
flat out uint tc_triangle_id[];

layout(location = 26) uniform bool cull_back_faces;
layout(location = 27) uniform float tolerance_px;
layout(location = 28) uniform float max_level;

layout(std430, binding = 4) buffer VertexCounters {
  uint visible_triangles;
  uint drawn_triangles;
  uint dropped_triangles;
  uint seam_copies;
};

vec3 q_from_eye(vec3 p_eye, float s_hint, bool use_hint);
vec3 st_from_eye(vec3 p_eye, float s_hint, bool use_hint);
bool faces_eye(vec3 p0, vec3 p1, vec3 p2);

// Level for the deviation d (px) of a projected point from its straight interpolation.
float level_for(float d) { return clamp(ceil(sqrt(d / tolerance_px)), 1.0, max_level); }

float edge_level(vec3 qa, vec3 qb, vec3 p_a, vec3 p_b, float s_hint) {
  vec3 q_mid = q_from_eye(0.5 * (p_a + p_b), s_hint, true);
  if (qa.z * qb.z * q_mid.z == 0.0) return max_level;
  return level_for(length(q_mid.xy - 0.5 * (qa.xy + qb.xy)));
}

void main() {
  tc_p_eye[gl_InvocationID] = g_p_eye[gl_InvocationID];
  tc_n_world[gl_InvocationID] = g_n_world[gl_InvocationID];
  tc_uv[gl_InvocationID] = g_uv[gl_InvocationID];
  tc_p_world[gl_InvocationID] = g_p_world[gl_InvocationID];
  tc_barycentric[gl_InvocationID] = g_barycentric[gl_InvocationID];
  tc_triangle_id[gl_InvocationID] = g_triangle_id[gl_InvocationID];
  if (gl_InvocationID != 0) return;

  vec3 p0 = g_p_eye[0], p1 = g_p_eye[1], p2 = g_p_eye[2];
  if (cull_back_faces && !faces_eye(p0, p1, p2)) {
    // A zero outer level discards the patch.
    gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = 0.0;
    gl_TessLevelInner[0] = 0.0;
    return;
  }
  atomicAdd(visible_triangles, 1u);
  float s_hint = st_from_eye(p0, 0.0, false).x;
  vec3 q0 = q_from_eye(p0, s_hint, true), q1 = q_from_eye(p1, s_hint, true),
       q2 = q_from_eye(p2, s_hint, true);
  // Outer level k belongs to the edge opposite vertex k (tessellation coordinate k = 0).
  float l0 = edge_level(q1, q2, p1, p2, s_hint);
  float l1 = edge_level(q2, q0, p2, p0, s_hint);
  float l2 = edge_level(q0, q1, p0, p1, s_hint);
  vec3 q_centre = q_from_eye((p0 + p1 + p2) / 3.0, s_hint, true);
  float l_inner = q0.z * q1.z * q2.z * q_centre.z == 0.0
                      ? max_level
                      : level_for(length(q_centre.xy - (q0.xy + q1.xy + q2.xy) / 3.0));
  gl_TessLevelOuter[0] = l0;
  gl_TessLevelOuter[1] = l1;
  gl_TessLevelOuter[2] = l2;
  gl_TessLevelInner[0] = max(max(l_inner, l0), max(l1, l2));
}
