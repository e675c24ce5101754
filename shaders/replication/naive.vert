// Naive multi-pass baseline: one glDrawArrays per (facet, record), pulling the record's
// triangles; the same arithmetic as replication/draw.vert, without any coverage work.
layout(location = 53) uniform uint drawn_facet;
layout(location = 54) uniform uint drawn_record;

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
out float gl_ClipDistance[4];

uint record_vertex(uint r, uint i);
uint record_object(uint r);
uint record_first_id(uint r);
vec3 eye_position(uint object, uint v);
vec3 world_normal(uint object, uint v);
vec3 world_position(uint object, uint v);
vec2 vertex_uv(uint v);
vec4 facet_clip(uint f, vec3 p_eye);
float facet_clip_distance(uint f, int k, vec3 p_eye);

void main() {
  uint object = record_object(drawn_record);
  uint v = record_vertex(drawn_record, uint(gl_VertexID));
  vec3 p_eye = eye_position(object, v);
  gl_Position = facet_clip(drawn_facet, p_eye);
  for (int k = 0; k < 4; ++k) gl_ClipDistance[k] = facet_clip_distance(drawn_facet, k, p_eye);
  v_n_world = world_normal(object, v);
  v_uv = vertex_uv(v);
  v_p_world = world_position(object, v);
  v_p_eye = p_eye;
  uint corner = uint(gl_VertexID) % 3u;
  v_barycentric = vec3(corner == 0u, corner == 1u, corner == 2u);
  v_triangle_id = record_first_id(drawn_record) + uint(gl_VertexID) / 3u;
}
