// Modern pipeline, pass 3: vertex pulling for glDrawArraysIndirect. Vertex 3i + c is corner c of
// replica i (GpuReplica: the triangle's first corner index, piece, object and ID); the piece's
// matrix and guarded clip planes place it in the output. Outputs are what scene/material.frag
// reads, plus the triangle ID.
layout(std430, binding = 11) readonly buffer Pairs { uvec4 replicas[]; };

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
out float gl_ClipDistance[4];

uint scene_index(uint i);
vec3 eye_position(uint object, uint v);
vec3 world_normal(uint object, uint v);
vec3 world_position(uint object, uint v);
vec2 vertex_uv(uint v);
vec4 facet_clip(uint f, vec3 p_eye);
float facet_clip_distance(uint f, int k, vec3 p_eye);

void main() {
  uvec4 replica = replicas[uint(gl_VertexID) / 3u];
  uint corner = uint(gl_VertexID) % 3u;
  uint v = scene_index(replica.x + corner);
  uint f = replica.y, object = replica.z;
  vec3 p_eye = eye_position(object, v);
  gl_Position = facet_clip(f, p_eye);
  for (int k = 0; k < 4; ++k) gl_ClipDistance[k] = facet_clip_distance(f, k, p_eye);
  v_n_world = world_normal(object, v);
  v_uv = vertex_uv(v);
  v_p_world = world_position(object, v);
  v_p_eye = p_eye;
  v_barycentric = vec3(corner == 0u, corner == 1u, corner == 2u);
  v_triangle_id = replica.w;
}
