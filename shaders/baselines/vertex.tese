// Per-vertex projection baseline, tessellation evaluation: a generated vertex on the flat scene
// triangle (barycentric in the eye frame, where the triangle really is straight); the geometry
// stage projects it. ccw keeps the patch's vertex order, so the 3D back-face rule still holds
// for every generated triangle.
layout(triangles, equal_spacing, ccw) in;

in vec3 tc_p_eye[];
in vec3 tc_n_world[];
in vec2 tc_uv[];
in vec3 tc_p_world[];
in vec3 tc_barycentric[];
flat in uint tc_triangle_id[];

out vec3 g_p_eye;
out vec3 g_n_world;
out vec2 g_uv;
out vec3 g_p_world;
out vec3 g_barycentric;
flat out uint g_triangle_id;

void main() {
  vec3 w = gl_TessCoord;
  g_p_eye = w.x * tc_p_eye[0] + w.y * tc_p_eye[1] + w.z * tc_p_eye[2];
  g_n_world = w.x * tc_n_world[0] + w.y * tc_n_world[1] + w.z * tc_n_world[2];
  g_uv = w.x * tc_uv[0] + w.y * tc_uv[1] + w.z * tc_uv[2];
  g_p_world = w.x * tc_p_world[0] + w.y * tc_p_world[1] + w.z * tc_p_world[2];
  g_barycentric = w.x * tc_barycentric[0] + w.y * tc_barycentric[1] + w.z * tc_barycentric[2];
  g_triangle_id = tc_triangle_id[0];
}
