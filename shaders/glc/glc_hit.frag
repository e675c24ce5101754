// GLC rasterization (the "glc" method), pass 2: every fragment of a triangle's quad casts its
// pixel's GLC ray and intersects the triangle exactly (Möller-Trumbore), so that the triangle
// covers exactly the pixel centres whose rays meet it: no holes, whatever the camera bends lines
// into. Depth is written from the hit's frame depth (reversed-Z: z_near / depth, greater is
// nearer), so the nearest hit along each ray wins the depth test.
//
// Shading goes through the material interface as in every other method (scene/material.frag is
// the rasterizers' counterpart of this file): the hit's barycentric coordinates interpolate the
// vertices' normals and texture coordinates, and their screen derivatives give edge_px.
// Derivatives (the texture's level of detail, edge_px, a material's own dFdx and fwidth) are
// differences within a 2×2 pixel quad, so every fragment of a quad that shades computes its ray's
// hit with the triangle's plane and runs shade(): a neighbour whose ray misses the triangle
// continues the hit fragment's plane coordinates smoothly, as a rasterizer's helper pixels do.
// Only quads whose four rays all miss are dropped before shading (a box is conservative, and on a
// mirror sphere's small triangles most of it misses); the others drop their missing fragments
// after shade().
flat in uint g_triangle_id;
flat in uint g_piece;
flat in vec3 g_a, g_b, g_c;  // the triangle, eye frame
flat in vec3 g_o0, g_ox, g_oy, g_d0, g_dx, g_dy;  // the piece's rays (glc/glc_quad.vert)
flat in vec3 g_n0, g_n1, g_n2;
flat in vec2 g_uv0, g_uv1, g_uv2;

layout(binding = 1) uniform isampler2D piece_of_pixel;  // GL rows (row 0 at the bottom)
layout(location = 0) uniform vec2 output_size;
layout(location = 1) uniform float z_near;
layout(location = 2) uniform bool cull_back_faces;
layout(location = 3) uniform mat4 T_world_eye;
// The scene material's, as scene/material.frag has them.
layout(location = 8) uniform vec4 base_colour;  // linear RGBA
layout(location = 9) uniform bool has_texture;
layout(binding = 0) uniform sampler2D base_texture;  // sRGB texture: sampling returns linear
layout(std140, binding = 0) uniform MaterialShading {
  uint unlit;  // 1: base colour times texture as authored, no lighting
};

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_triangle_id;

void main() {
  const vec2 p = vec2(gl_FragCoord.x, output_size.y - gl_FragCoord.y);
  const vec3 origin = g_o0 + p.x * g_ox + p.y * g_oy;
  const vec3 direction = g_d0 + p.x * g_dx + p.y * g_dy;
  const vec3 e1 = g_b - g_a, e2 = g_c - g_a;
  const vec3 n = cross(e1, e2);
  const bool front = dot(n, direction) < 0.0;
  const vec3 pv = cross(direction, e2);
  const float det = dot(e1, pv);
  // A ray parallel to the plane has no hit; its numbers stay finite for its neighbours' sake.
  const float divisor = det == 0.0 ? 1.0 : det;
  const vec3 s = origin - g_a;
  const float u = dot(s, pv) / divisor;
  const vec3 qv = cross(s, e1);
  const float v = dot(direction, qv) / divisor;
  const float t = dot(e2, qv) / divisor;
  const bool hit = texelFetch(piece_of_pixel, ivec2(gl_FragCoord.xy), 0).r == int(g_piece) &&
                   (!cull_back_faces || front) && det != 0.0 && u >= 0.0 && u <= 1.0 &&
                   v >= 0.0 && u + v <= 1.0 && t >= z_near;
  // Whether any fragment of this one's 2×2 quad hits, the same in all four: for h in {0, 1},
  // h + |h' - h| over a row pair is positive where either hits, and the same over the column.
  const float h = hit ? 1.0 : 0.0;
  const float row = h + abs(dFdxFine(h));
  if (!(row + abs(dFdyFine(row)) > 0.0)) discard;

  const vec3 barycentric = vec3(1.0 - u - v, u, v);
  const vec3 p_eye = origin + t * direction;
  MaterialInput m;
  m.p_world = (T_world_eye * vec4(p_eye, 1.0)).xyz;
  const vec3 normal = normalize(barycentric.x * g_n0 + barycentric.y * g_n1 + barycentric.z * g_n2);
  // Two-sided, as gl_FrontFacing turns it in scene/material.frag.
  m.n_world = front ? normal : -normal;
  m.uv = barycentric.x * g_uv0 + barycentric.y * g_uv1 + barycentric.z * g_uv2;
  m.barycentric = barycentric;
  const vec3 gradient = sqrt(dFdx(barycentric) * dFdx(barycentric) +
                             dFdy(barycentric) * dFdy(barycentric));
  m.edge_px = barycentric / max(gradient, vec3(1e-9));
  m.distance_m = length(p_eye);
  m.depth = z_near / t;
  m.q_px = gl_FragCoord.xy;
  m.triangle_id = g_triangle_id;
  m.base_colour = base_colour;
  if (has_texture) m.base_colour *= texture(base_texture, m.uv);
  m.unlit = unlit != 0u;
  const vec4 colour = shade(m);
  if (!hit) discard;
  gl_FragDepth = m.depth;
  out_colour = colour;
  out_triangle_id = g_triangle_id;
}
