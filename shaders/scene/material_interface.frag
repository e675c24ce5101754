// The interface of a material: what every material's fragment shader (the built-ins under
// scene/materials/ and a user's FILE.frag) is compiled against. This text is put in front of the
// material's own, then `#line 1`, so compiler messages give the material file's lines. The
// material defines one function, shade(); scene/material.frag gathers the inputs, calls it and
// writes colour and triangle ID, so no material can change the IDs or the depth (`discard` and
// gl_FragDepth are refused before compiling).
//
// Frames and units as in DESIGN.md: metres, the world frame of the scene, the eye frame of the
// view. "Output pixels" are the pixels of the image being rasterized: a projector's output for the
// facet methods, naive and vertex, a GLC camera's image for glc; a cube face's pixels for the cube
// map, which are then resampled into the output (so its strokes are not of the width asked for).
struct MaterialInput {
  vec3 p_world;       // position, world frame, metres
  vec3 n_world;       // unit normal, world frame, turned towards the eye (two-sided)
  vec2 uv;            // the scene's texture coordinates
  vec3 barycentric;   // in the scene triangle: 1 at corner k, 0 on the edge opposite it
  vec3 edge_px;       // distance to the edge opposite each corner, output pixels
  float distance_m;   // from the eye, metres
  float depth;        // gl_FragCoord.z: reversed-Z, greater is nearer
  vec2 q_px;          // pixel position, gl_FragCoord.xy (row 0 at the bottom)
  uint triangle_id;   // the triangle's ID (driver/render_method.hpp); 0 where none is kept
  vec4 base_colour;   // the scene material's base colour times its texture, linear RGBA
  bool unlit;         // the scene material is shown as authored (KHR_materials_unlit)
};

// The material: linear RGBA for this fragment (alpha is written as given).
vec4 shade(MaterialInput m);

// The default shading (the `lit` material): base colour under a fixed sun and sky, or as
// authored when unlit. Defined in scene/sun_and_sky.frag; any material may call it.
vec3 sun_and_sky(MaterialInput m);
