// GLC two-pass rasterization ("glc-2pass", Yu, Yu & McMillan), pass 1: the scene through one GLC
// piece's proxy pinhole (a perspective camera whose frustum holds every point the piece sees),
// pulled as baselines/cube_face.vert pulls it. Per vertex it computes the piece's GLC projection
// coefficients: at frame depth z the rays meet the plane z in P(α, β; z) = P0(z) + M(z)·(α, β),
// so a frame point q has M(q.z)·(α, β) = q.xy − P0(q.z), with M(z) = M0 + z·M1 and
// P0(z) = st0 + z·duv0. M's entries and the right-hand side are affine in the point, so the
// rasterizer's perspective-correct interpolation gives every sample its own coefficients exactly,
// and glc/glc_sample.frag solves them. Points at frame depth below z_near are clipped (clip
// distance 0): the GLC does not see them, and they must not hide what it does see.
layout(location = 0) uniform mat4 T_clip_object;  // proxy projection · T_eye_object
layout(location = 1) uniform mat4 T_world_object;
layout(location = 3) uniform uint first_id;
layout(location = 4) uniform mat4 T_eye_object;
layout(location = 10) uniform mat4 T_frame_eye;  // the piece's GLC frame
layout(location = 11) uniform mat2 glc_m0;
layout(location = 12) uniform mat2 glc_m1;
layout(location = 13) uniform vec2 glc_st0;
layout(location = 14) uniform vec2 glc_duv0;
layout(location = 16) uniform float glc_z_near;

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
out vec4 v_glc_m;    // M(z): columns (x, y) and (z, w)
out vec3 v_glc_rhs;  // q.xy − P0(z), and z

uint pulled_vertex();
vec3 pulled_position(uint v);
vec3 pulled_normal(uint v);
vec2 pulled_uv(uint v);

void main() {
  uint v = pulled_vertex();
  vec4 p_object = vec4(pulled_position(v), 1.0);
  gl_Position = T_clip_object * p_object;
  v_n_world = mat3(T_world_object) * pulled_normal(v);
  v_uv = pulled_uv(v);
  v_p_world = (T_world_object * p_object).xyz;
  v_p_eye = (T_eye_object * p_object).xyz;
  uint corner = uint(gl_VertexID) % 3u;
  v_barycentric = vec3(corner == 0u, corner == 1u, corner == 2u);
  v_triangle_id = first_id + uint(gl_VertexID) / 3u;
  const vec3 q = (T_frame_eye * vec4(v_p_eye, 1.0)).xyz;
  const mat2 m = glc_m0 + q.z * glc_m1;
  v_glc_m = vec4(m[0], m[1]);
  v_glc_rhs = vec3(q.xy - glc_st0 - q.z * glc_duv0, q.z);
  gl_ClipDistance[0] = q.z - glc_z_near;
}
