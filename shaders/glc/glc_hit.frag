// GLC rasterization (the "glc" method), pass 2: every fragment of a triangle's quad casts its
// pixel's GLC ray and intersects the triangle exactly (Möller-Trumbore), so that the triangle
// covers exactly the pixel centres whose rays meet it: no holes, whatever the camera bends lines
// into. Depth is written from the hit's frame depth (reversed-Z: z_near / depth, greater is
// nearer), so the nearest hit along each ray wins the depth test.
struct Quad {
  vec4 box;
  vec4 a, b, c;  // the triangle's vertices (eye frame; w unused)
  uvec4 ids;     // triangle ID, piece, material, unused
};
// A piece's rays, affine in the image pixel p (x right, y down, continuous): origin o0 + p.x·ox +
// p.y·oy, direction d0 + p.x·dx + p.y·dy (frame-z component 1: the ray parameter is the depth).
struct Piece {
  vec4 o0, ox, oy, d0, dx, dy;
};
layout(std430, binding = 0) readonly buffer Quads { Quad quads[]; };
layout(std430, binding = 1) readonly buffer Pieces { Piece pieces[]; };
layout(std430, binding = 2) readonly buffer Materials { vec4 base_colours[]; };
layout(binding = 0) uniform isampler2D piece_of_pixel;  // GL rows (row 0 at the bottom)
layout(location = 0) uniform vec2 output_size;
layout(location = 1) uniform float z_near;
layout(location = 2) uniform bool cull_back_faces;

flat in uint quad_index;
layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

void main() {
  const Quad q = quads[quad_index];
  const uint piece = q.ids.y;
  if (texelFetch(piece_of_pixel, ivec2(gl_FragCoord.xy), 0).r != int(piece)) discard;
  const vec2 p = vec2(gl_FragCoord.x, output_size.y - gl_FragCoord.y);
  const Piece g = pieces[piece];
  const vec3 origin = g.o0.xyz + p.x * g.ox.xyz + p.y * g.oy.xyz;
  const vec3 direction = g.d0.xyz + p.x * g.dx.xyz + p.y * g.dy.xyz;
  const vec3 e1 = q.b.xyz - q.a.xyz, e2 = q.c.xyz - q.a.xyz;
  const vec3 n = cross(e1, e2);
  if (cull_back_faces && !(dot(n, direction) < 0.0)) discard;
  const vec3 pv = cross(direction, e2);
  const float det = dot(e1, pv);
  if (det == 0.0) discard;
  const vec3 s = origin - q.a.xyz;
  const float u = dot(s, pv) / det;
  if (u < 0.0 || u > 1.0) discard;
  const vec3 qv = cross(s, e1);
  const float v = dot(direction, qv) / det;
  if (v < 0.0 || u + v > 1.0) discard;
  const float t = dot(e2, qv) / det;
  if (!(t >= z_near)) discard;
  gl_FragDepth = z_near / t;
  // Lit by a fixed light in the eye frame (upper left, behind the viewer); textures are
  // not sampled (IDs, which --reference compares, do not depend on them).
  const vec4 base = base_colours[q.ids.z];
  const vec3 unit_n = normalize(n) * (dot(n, direction) < 0.0 ? 1.0 : -1.0);
  const float light = 0.25 + 0.75 * max(dot(unit_n, normalize(vec3(-0.4, 0.8, 0.45))), 0.0);
  out_colour = vec4(base.rgb * light, 1.0);
  out_triangle_id = q.ids.x;
}
