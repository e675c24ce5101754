// Per-vertex projection baseline, geometry stage: projects the three vertices of a triangle with
// the exact map P (vertex_projection.vert) and emits it in output pixels, with straight edges
// between the projected vertices (the method's error; tessellation makes the pieces small).
//
// - Branches: vertices 1 and 2 take the azimuth branch nearest vertex 0's, so a triangle across
//   a panorama's seam stays whole; on a wrapping base it is then emitted once more for every
//   whole turn that brings part of it back into [0,1] in s: drawn at both edges of the output.
// - A triangle with a vertex where P has no value (behind a perspective base's image plane, on a
//   cylinder's axis, straight behind a fisheye) is dropped, and so is one that surrounds such a
//   direction (vertex_projection.vert, surrounds_singularity): its straight-edged image would
//   cut across the output. Without tessellation that leaves a hole where the reference shows the
//   triangle (for example the ground round a cylinder's axis below the eye); with it, only the
//   small piece round the singular direction, which lies outside the output, goes. Likewise a
//   triangle with a vertex beyond the guard limit near a singular direction (beyond_guard).
// - Depth is reversed-Z from the distance to the eye: z_ndc = z_near / |p_eye| with w = 1, so
//   points nearer than z_near are clipped by the rasterizer's z <= w plane. Between vertices it
//   is interpolated linearly in output pixels, an approximation of the exact z_near / |p|.
layout(triangles) in;
layout(triangle_strip, max_vertices = 9) out;

#ifndef TESSELLATED
#define TESSELLATED 0
#endif

in vec3 g_p_eye[];
in vec3 g_n_world[];
in vec2 g_uv[];
in vec3 g_p_world[];
in vec3 g_barycentric[];
flat in uint g_triangle_id[];

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;

layout(location = 23) uniform vec2 output_size;  // as in vertex_projection.vert
layout(location = 24) uniform float s_period;
layout(location = 26) uniform bool cull_back_faces;
layout(location = 29) uniform float z_near;

// Counted per frame and read back for RenderStats.
layout(std430, binding = 4) buffer VertexCounters {
  uint visible_triangles;  // scene triangles (patches) past back-face culling
  uint drawn_triangles;    // triangles emitted to the rasterizer, seam copies included
  uint dropped_triangles;  // triangles (tessellated pieces) dropped near a singular direction
  uint seam_copies;        // emissions beyond a triangle's first on a 360° base
};

vec3 q_from_eye(vec3 p_eye, float s_hint, bool use_hint);
vec2 q_from_st(vec2 st);
vec3 st_from_eye(vec3 p_eye, float s_hint, bool use_hint);
bool faces_eye(vec3 p0, vec3 p1, vec3 p2);
bool surrounds_singularity(vec3 p0, vec3 p1, vec3 p2);
bool beyond_guard(vec2 st);

// True when the triangle was drawn (some part of it may lie in the output).
bool emit(vec3 st[3], float shift) {
  vec2 q[3];
  for (int k = 0; k < 3; ++k) q[k] = q_from_st(st[k].xy + vec2(shift, 0.0));
  // Wholly beyond one edge of the output: not drawn.
  vec2 q_min = min(min(q[0], q[1]), q[2]), q_max = max(max(q[0], q[1]), q[2]);
  if (q_max.x < 0.0 || q_max.y < 0.0 || q_min.x > output_size.x || q_min.y > output_size.y) {
    return false;
  }
  for (int k = 0; k < 3; ++k) {
    // y flips once: output rows run down, GL window rows up.
    vec2 ndc = vec2(2.0 * q[k].x / output_size.x - 1.0, 1.0 - 2.0 * q[k].y / output_size.y);
    gl_Position = vec4(ndc, z_near / length(g_p_eye[k]), 1.0);
    v_n_world = g_n_world[k];
    v_uv = g_uv[k];
    v_p_world = g_p_world[k];
    v_p_eye = g_p_eye[k];
    v_barycentric = g_barycentric[k];
    v_triangle_id = g_triangle_id[0];
    EmitVertex();
  }
  EndPrimitive();
  atomicAdd(drawn_triangles, 1u);
  return true;
}

void main() {
#if !TESSELLATED
  // With tessellation, the control stage has culled and counted the whole patch already.
  if (cull_back_faces && !faces_eye(g_p_eye[0], g_p_eye[1], g_p_eye[2])) return;
  atomicAdd(visible_triangles, 1u);
#endif
  vec3 st[3];
  st[0] = st_from_eye(g_p_eye[0], 0.0, false);
  st[1] = st_from_eye(g_p_eye[1], st[0].x, true);
  st[2] = st_from_eye(g_p_eye[2], st[0].x, true);
  if (st[0].z * st[1].z * st[2].z == 0.0 ||
      surrounds_singularity(g_p_eye[0], g_p_eye[1], g_p_eye[2]) || beyond_guard(st[0].xy) ||
      beyond_guard(st[1].xy) || beyond_guard(st[2].xy)) {
    atomicAdd(dropped_triangles, 1u);
    return;
  }
  if (s_period == 0.0) {
    emit(st, 0.0);
    return;
  }
  // Every whole turn k with [s_min, s_max] + k·period meeting [0,1]; at most 3 (the output
  // holds max_vertices = 9).
  float s_min = min(min(st[0].x, st[1].x), st[2].x), s_max = max(max(st[0].x, st[1].x), st[2].x);
  int k_first = int(ceil(-s_max / s_period)), k_last = int(floor((1.0 - s_min) / s_period));
  k_last = min(k_last, k_first + 2);
  uint drawn = 0u;
  for (int k = k_first; k <= k_last; ++k) drawn += emit(st, float(k) * s_period) ? 1u : 0u;
  if (drawn > 1u) atomicAdd(seam_copies, drawn - 1u);
}
