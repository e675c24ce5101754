// Tessellator form, geometry stage: segment s of isoline l is replica k = first + l·segments + s
// of the patch's triangle (isoline l lies at v = l / lines, segment s starts at u = s / segments).
// The k-th covered facet is found by the same walk as the control stage, and the triangle is
// emitted through that facet's matrix and clip planes, as replication/draw.geom does.
layout(lines) in;
layout(triangle_strip, max_vertices = 3) out;

in vec2 te_uv[];
flat in uvec4 te_replicas[];  // (triangle, first replica, replicas, segments per line)
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
  uvec4 table = te_replicas[0];
  uint count = table.z, segments = table.w;
  uint lines = (count + segments - 1u) / segments;
  uint line = uint(round(te_uv[0].y * float(lines)));
  uint segment = uint(round(min(te_uv[0].x, te_uv[1].x) * float(segments)));
  uint k = line * segments + segment;
  if (k >= count) return;
  uint t = table.x;
  vec3 p[3];
  uint e = triangle_eye(t, p);
  uint f;
  cover(p, t, e, 0xffffffffu, table.y + k, f);
  if (f == 0xffffffffu) return;
  uint object = object_of(e);
  for (uint c = 0u; c < 3u; ++c) {
    uint v = vertex_of(e, t, c);
    vec3 p_eye = eye_position(object, v);
    gl_Position = facet_clip(f, p_eye);
    for (int i = 0; i < 4; ++i) gl_ClipDistance[i] = facet_clip_distance(f, i, p_eye);
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
