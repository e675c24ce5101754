// Cube-map baseline, pass 1 with a geometry stage: per-face culling of triangles and, for layered
// creation, the choice of face. Every face in face_mask whose frustum the triangle may meet gets
// the triangle, projected with the matrix of cube_face.vert's one-face projection (the same clip
// coordinates, so the same pixels) and sent to layer f of the cube (gl_Layer; 0 when one face is
// bound). A triangle is left out of a face only when all three vertices lie beyond one plane of
// the face's frustum (a side plane or the near plane): the clipper would discard all of it, so
// the pixels are those of drawing it into every face. Layered framebuffers take the faces of the
// cube maps (colour, IDs, depth) at once.
layout(triangles) in;
layout(triangle_strip, max_vertices = 18) out;

in vec3 g_n_world[];
in vec2 g_uv[];
in vec3 g_p_world[];
in vec3 g_p_eye[];
in vec3 g_barycentric[];
flat in uint g_triangle_id[];
in vec4 g_p_object[];

out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;

layout(location = 5) uniform uint face_mask;  // bit f: draw into face f (GL order +X..-Z)
layout(location = 6) uniform bool layered;    // write gl_Layer = f (else 0: one face bound)
layout(location = 7) uniform bool cull_triangles;  // false: every triangle into every face
// Per face f: its projection times T_eye_object, as T_clip_object of cube_face.vert.
layout(location = 10) uniform mat4 T_clip_object_face[6];

void main() {
  for (int f = 0; f < 6; ++f) {
    if ((face_mask & (1u << uint(f))) == 0u) continue;
    vec4 clip[3];
    for (int k = 0; k < 3; ++k) {
      clip[k] = T_clip_object_face[f] * g_p_object[k];
    }
    // Trivial rejection against x = ±w, y = ±w and z <= w (the near plane).
    bvec4 out0 = bvec4(clip[0].x > clip[0].w, clip[0].x < -clip[0].w, clip[0].y > clip[0].w,
                       clip[0].y < -clip[0].w);
    bvec4 out1 = bvec4(clip[1].x > clip[1].w, clip[1].x < -clip[1].w, clip[1].y > clip[1].w,
                       clip[1].y < -clip[1].w);
    bvec4 out2 = bvec4(clip[2].x > clip[2].w, clip[2].x < -clip[2].w, clip[2].y > clip[2].w,
                       clip[2].y < -clip[2].w);
    if (cull_triangles) {
      if (any(bvec4(uvec4(out0) & uvec4(out1) & uvec4(out2)))) continue;
      if (clip[0].z > clip[0].w && clip[1].z > clip[1].w && clip[2].z > clip[2].w) continue;
    }
    for (int k = 0; k < 3; ++k) {
      gl_Position = clip[k];
      gl_Layer = layered ? f : 0;
      v_n_world = g_n_world[k];
      v_uv = g_uv[k];
      v_p_world = g_p_world[k];
      v_p_eye = g_p_eye[k];
      v_barycentric = g_barycentric[k];
      v_triangle_id = g_triangle_id[k];
      EmitVertex();
    }
    EndPrimitive();
  }
}
