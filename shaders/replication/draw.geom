// Seed pipeline, pass 3: one point per replica (t, k); the geometry shader finds triangle t's
// k-th facet by the same walk as pass 1 and emits the triangle through that facet's matrix and
// clip planes. Same arithmetic as replication/draw.vert, so both pipelines give the same image.
layout(points) in;
layout(triangle_strip, max_vertices = 3) out;

layout(std430, binding = 11) readonly buffer Pairs { uvec2 pairs[]; };

flat in uint v_index[];
out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
out float gl_ClipDistance[4];

uint vertex_of(uint e, uint t, uint c);
uint triangle_id(uint e, uint t);
uint object_of(uint e);
vec3 eye_position(uint object, uint v);
vec3 world_normal(uint object, uint v);
vec3 world_position(uint object, uint v);
vec2 vertex_uv(uint v);
vec4 facet_clip(uint f, vec3 p_eye);
float facet_clip_distance(uint f, int k, vec3 p_eye);
uint triangle_eye(uint t, out vec3 p[3]);
uint cover(vec3 p[3], uint t, uint e, uint pair_base, uint wanted, out uint wanted_facet);
void write_pair(uint at, uint t, uint facet) {}

void main() {
  uvec2 replica = pairs[v_index[0]];
  uint t = replica.x;
  vec3 p[3];
  uint e = triangle_eye(t, p);
  uint f;
  cover(p, t, e, 0xffffffffu, replica.y, f);
  if (f == 0xffffffffu) return;
  uint object = object_of(e);
  for (uint c = 0u; c < 3u; ++c) {
    uint v = vertex_of(e, t, c);
    vec3 p_eye = eye_position(object, v);
    gl_Position = facet_clip(f, p_eye);
    for (int k = 0; k < 4; ++k) gl_ClipDistance[k] = facet_clip_distance(f, k, p_eye);
    v_n_world = world_normal(object, v);
    v_uv = vertex_uv(v);
    v_p_world = world_position(object, v);
    v_p_eye = p_eye;
    v_barycentric = vec3(c == 0u, c == 1u, c == 2u);
    v_triangle_id = triangle_id(e, t);
    EmitVertex();
  }
  EndPrimitive();
}
