// Per-vertex projection baseline, vertex stage: pulls one vertex of a primitive (glDrawArrays of
// index_count vertices, or GL_PATCHES of 3) and moves it into the eye frame. The projection
// itself happens in the geometry stage (and the tessellation stages), which see whole
// triangles: a triangle across a wrapping panorama's seam needs all three vertices.
layout(location = 0) uniform mat4 T_eye_object;
layout(location = 1) uniform mat4 T_world_object;
layout(location = 3) uniform uint first_id;

out vec3 g_p_eye;
out vec3 g_n_world;
out vec2 g_uv;
out vec3 g_p_world;
out vec3 g_barycentric;
flat out uint g_triangle_id;

uint pulled_vertex();
vec3 pulled_position(uint v);
vec3 pulled_normal(uint v);
vec2 pulled_uv(uint v);

void main() {
  uint v = pulled_vertex();
  vec4 p_object = vec4(pulled_position(v), 1.0);
  g_p_eye = (T_eye_object * p_object).xyz;
  g_p_world = (T_world_object * p_object).xyz;
  uint corner = uint(gl_VertexID) % 3u;
  g_barycentric = vec3(corner == 0u, corner == 1u, corner == 2u);
  g_n_world = mat3(T_world_object) * pulled_normal(v);
  g_uv = pulled_uv(v);
  g_triangle_id = first_id + uint(gl_VertexID) / 3u;
}
