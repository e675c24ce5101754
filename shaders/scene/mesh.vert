// Plain perspective rendering of scene meshes (previews, reference images, baselines). Pulls
// nothing: attributes come from the scene's vertex array (see driver/gpu_scene.hpp).
layout(location = 0) in vec3 p_object;
layout(location = 1) in vec3 n_object;
layout(location = 2) in vec2 uv;

// T_clip_object = projection * T_eye_world * T_world_object; T_world_object for lighting.
layout(location = 0) uniform mat4 T_clip_object;
layout(location = 1) uniform mat4 T_world_object;
layout(location = 2) uniform mat4 T_eye_object;

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
// Barycentric coordinates of the triangle for non-indexed draws (corner gl_VertexID mod 3).
out vec3 v_barycentric;

void main() {
  // Objects carry rigid transforms with uniform scale at most, so the normal needs no inverse
  // transpose; it is normalised in the fragment shader.
  v_n_world = mat3(T_world_object) * n_object;
  v_uv = uv;
  v_p_world = (T_world_object * vec4(p_object, 1.0)).xyz;
  v_p_eye = (T_eye_object * vec4(p_object, 1.0)).xyz;
  int corner = gl_VertexID % 3;
  v_barycentric = vec3(corner == 0, corner == 1, corner == 2);
  gl_Position = T_clip_object * vec4(p_object, 1.0);
}
