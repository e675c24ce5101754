// Cube-map baseline, pass 1: the scene into the cube faces. Pulls triangles of one primitive
// (glDrawArrays of index_count vertices); the triangle ID is the primitive's first ID plus the
// triangle's ordinal. Without a geometry stage it projects onto one face (T_clip_object); with
// one (CUBE_GS, cube_face.geom) it passes the object-frame position on and the geometry stage
// projects each triangle onto every face it meets.
layout(location = 0) uniform mat4 T_clip_object;  // face projection · T_eye_object
layout(location = 1) uniform mat4 T_world_object;
layout(location = 3) uniform uint first_id;
layout(location = 4) uniform mat4 T_eye_object;

#ifndef CUBE_GS
#define CUBE_GS 0
#endif
#if CUBE_GS
// The geometry stage's inputs; it writes the v_* outputs the material stage reads.
#define v_n_world g_n_world
#define v_uv g_uv
#define v_p_world g_p_world
#define v_p_eye g_p_eye
#define v_barycentric g_barycentric
#define v_triangle_id g_triangle_id
out vec4 g_p_object;
#endif
out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;

uint pulled_vertex();
vec3 pulled_position(uint v);
vec3 pulled_normal(uint v);
vec2 pulled_uv(uint v);

void main() {
  uint v = pulled_vertex();
  vec4 p_object = vec4(pulled_position(v), 1.0);
#if CUBE_GS
  g_p_object = p_object;
  gl_Position = p_object;
#else
  gl_Position = T_clip_object * p_object;
#endif
  v_n_world = mat3(T_world_object) * pulled_normal(v);
  v_uv = pulled_uv(v);
  v_p_world = (T_world_object * p_object).xyz;
  v_p_eye = (T_eye_object * p_object).xyz;
  uint corner = uint(gl_VertexID) % 3u;
  v_barycentric = vec3(corner == 0u, corner == 1u, corner == 2u);
  v_triangle_id = first_id + uint(gl_VertexID) / 3u;
}
