// GLC two-pass rasterization ("glc-2pass"), pass 1's own output beside the colour and the ID
// (scene/material.frag calls write_extra_outputs): the sample's GLC image point, solved from the
// interpolated projection coefficients (glc/glc_sample.vert), in output pixels (x right, y down,
// (0, 0) the top-left corner), and its frame depth. w is 1 for a sample with an image point and
// -1 where the piece's projection is singular there (on or beside a slit depth); samples that
// see nothing keep the clear value, w = 0.
in vec4 v_glc_m;
in vec3 v_glc_rhs;

layout(location = 15) uniform mat3 glc_pixel_from_ab;

layout(location = 2) out vec4 out_glc_sample;

void write_extra_outputs() {
  const mat2 m = mat2(v_glc_m.xy, v_glc_m.zw);
  const float det = determinant(m);
  // Singular where |det| is at most 1e-6 of the squared entries (float's rounding of M).
  if (!(abs(det) > 1e-6 * dot(v_glc_m, v_glc_m))) {
    out_glc_sample = vec4(0.0, 0.0, v_glc_rhs.z, -1.0);
    return;
  }
  const vec2 ab = inverse(m) * v_glc_rhs.xy;
  const vec3 pixel = glc_pixel_from_ab * vec3(ab, 1.0);
  out_glc_sample = vec4(pixel.xy, v_glc_rhs.z, 1.0);
}
