// GLC rasterization (the "glc" method), pass 1: one screen-aligned quad per (triangle, piece), the
// triangle's conservative pixel bound in that GLC piece clipped to the piece's region (computed on
// the CPU, Glc::triangle_bounds). Vertices are pulled: vertices 4k..4k+3 are quad k's corners,
// drawn as two triangles by an index buffer (llvmpipe shades each index once per batch). What the
// fragments need of the triangle and the piece is passed flat, so that no fragment reads storage
// buffers: the eye-frame vertices for the ray cast, and the scene vertices' world normals and
// texture coordinates (pulled from the scene's buffers, GpuScene::bind_for_pulling) for shading.
struct Quad {
  vec4 box;  // x0, y0, x1, y1 in GL window coordinates (y up), continuous
  vec4 a, b, c;  // the triangle's vertices (eye frame; w unused)
  uvec4 ids;     // triangle ID, piece, material, unused
  uvec4 source;  // the triangle's first index in the scene's indices, its object, unused
};
// A piece's rays, affine in the image pixel p (x right, y down, continuous): origin o0 + p.x·ox +
// p.y·oy, direction d0 + p.x·dx + p.y·dy (frame-z component 1: the ray parameter is the depth).
struct Piece {
  vec4 o0, ox, oy, d0, dx, dy;
};
struct SceneObject {  // GpuObject (driver/gpu_scene.hpp)
  mat4 T_world_object;
  vec4 bounds_min, bounds_max;
  uvec4 primitives;
};
layout(std430, binding = 0) readonly buffer Quads { Quad quads[]; };
layout(std430, binding = 1) readonly buffer Pieces { Piece pieces[]; };
layout(std430, binding = 3) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 4) readonly buffer Objects { SceneObject objects[]; };
layout(binding = 9) uniform samplerBuffer normal_texels;  // RGB32F, object frame
layout(binding = 10) uniform samplerBuffer uv_texels;     // RG32F
layout(location = 0) uniform vec2 output_size;

flat out uint g_triangle_id;
flat out uint g_piece;
flat out vec3 g_a, g_b, g_c;
flat out vec3 g_o0, g_ox, g_oy, g_d0, g_dx, g_dy;
flat out vec3 g_n0, g_n1, g_n2;  // world frame, not normalised
flat out vec2 g_uv0, g_uv1, g_uv2;

void main() {
  const uint k = uint(gl_VertexID) / 4u;
  // Corners (x0,y0) (x1,y0) (x0,y1) (x1,y1).
  const uint c = uint(gl_VertexID) % 4u;
  const Quad q = quads[k];
  const vec4 box = q.box;
  const vec2 p = vec2((c & 1u) != 0u ? box.z : box.x, (c & 2u) != 0u ? box.w : box.y);
  g_triangle_id = q.ids.x;
  g_piece = q.ids.y;
  g_a = q.a.xyz;
  g_b = q.b.xyz;
  g_c = q.c.xyz;
  const Piece g = pieces[q.ids.y];
  g_o0 = g.o0.xyz;
  g_ox = g.ox.xyz;
  g_oy = g.oy.xyz;
  g_d0 = g.d0.xyz;
  g_dx = g.dx.xyz;
  g_dy = g.dy.xyz;
  // Objects carry rigid transforms with uniform scale at most (as scene/mesh.vert assumes).
  const mat3 R_world_object = mat3(objects[q.source.y].T_world_object);
  const uint i0 = indices[q.source.x], i1 = indices[q.source.x + 1u],
             i2 = indices[q.source.x + 2u];
  g_n0 = R_world_object * texelFetch(normal_texels, int(i0)).xyz;
  g_n1 = R_world_object * texelFetch(normal_texels, int(i1)).xyz;
  g_n2 = R_world_object * texelFetch(normal_texels, int(i2)).xyz;
  g_uv0 = texelFetch(uv_texels, int(i0)).xy;
  g_uv1 = texelFetch(uv_texels, int(i1)).xy;
  g_uv2 = texelFetch(uv_texels, int(i2)).xy;
  gl_Position = vec4(2.0 * p / output_size - 1.0, 0.0, 1.0);
}
