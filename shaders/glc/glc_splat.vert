// GLC two-pass rasterization ("glc-2pass", Yu, Yu & McMillan), pass 2: one GLC piece's pass-1
// samples moved to their GLC image points, neighbouring samples joined into triangles so that no
// holes open between them. The piece's samples fill a rectangle of the sample atlas; vertex v is
// its sample v (row by row), and an index buffer makes every cell of four neighbouring samples
// two triangles, so that each sample is moved once. A sample that saw nothing lies at infinity
// along its proxy ray: its image point is the pixel whose GLC ray has that direction (the ray
// directions are affine in (α, β): M1·(α, β) = d.xy / d.z − duv0), at the farthest depth. A
// sample without an image point (a singular projection, a direction the GLC never takes) gets
// clip distance −1e20, which clips its triangles away.
layout(binding = 0) uniform sampler2D glc_samples;  // pass 1's RGBA32F: pixel.xy, depth, kind
layout(location = 0) uniform vec2 output_size;
layout(location = 1) uniform float z_near;
layout(location = 2) uniform ivec4 rect;  // the piece's samples: x0, y0, width, height (texels)
layout(location = 4) uniform mat3 R_frame_proxy;  // proxy frame to GLC frame
layout(location = 5) uniform vec4 tan_extent;  // proxy image: left, right, bottom, top tangents
layout(location = 6) uniform mat2 glc_m1;
layout(location = 7) uniform vec2 glc_duv0;
layout(location = 8) uniform mat3 glc_pixel_from_ab;

noperspective out vec2 v_texel;  // atlas texel coordinates (texel centres at integers)

// Reversed-Z depth of what lies at infinity: below every finite depth z_near / z.
const float kInfinityDepth = 1e-30;
// Image points are kept within this many output sizes of the image, so that far samples stay
// finite for the clipper.
const float kFarPixels = 64.0;

// Where sample `texel` goes: (pixel.xy, depth), and whether it has a place.
bool place(ivec2 texel, out vec3 placed) {
  const vec4 s = texelFetch(glc_samples, texel, 0);
  if (s.w > 0.5) {
    placed = vec3(s.xy, z_near / s.z);
  } else if (s.w > -0.5) {
    const vec2 f = (vec2(texel - rect.xy) + 0.5) / vec2(rect.zw);
    const vec2 t = mix(tan_extent.xz, tan_extent.yw, f);
    const vec3 d = R_frame_proxy * vec3(t, -1.0);
    const float det = determinant(glc_m1);
    if (!(d.z > 0.0) || !(abs(det) > 1e-6 * dot(vec4(glc_m1[0], glc_m1[1]), vec4(glc_m1[0], glc_m1[1])))) {
      return false;
    }
    const vec2 ab = inverse(glc_m1) * (d.xy / d.z - glc_duv0);
    placed = vec3((glc_pixel_from_ab * vec3(ab, 1.0)).xy, kInfinityDepth);
  } else {
    return false;
  }
  placed.xy = clamp(placed.xy, -kFarPixels * output_size, (kFarPixels + 1.0) * output_size);
  return true;
}

void main() {
  const ivec2 texel = rect.xy + ivec2(gl_VertexID % rect.z, gl_VertexID / rect.z);
  v_texel = vec2(texel);
  vec3 placed;
  if (!place(texel, placed)) {
    gl_ClipDistance[0] = -1e20;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  gl_ClipDistance[0] = 1.0;
  gl_Position = vec4(2.0 * placed.x / output_size.x - 1.0, 1.0 - 2.0 * placed.y / output_size.y,
                     placed.z, 1.0);
}
