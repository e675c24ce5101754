// Per-vertex projection baseline: the exact map P of a warp (FORMATS.md §2, facet/projection/warp.hpp)
// in GLSL, from an eye-frame point to output pixels. Not a program of its own: linked as a second
// shader object into every stage that projects (tessellation control, geometry).
//
// Units and frames: p_eye in metres, eye frame (x right, y up, looking down -z); st the base
// image's normalised coordinates (t downwards); q output pixels, (0,0) the top-left corner.
// Floats throughout: at 4096 px a float s·W is good to about 5e-4 px.

// Rotation of eye-frame vectors into the base frame (the transpose of the warp's R_eye_base).
layout(location = 20) uniform mat3 R_base_eye;
// 0 perspective, 1 fisheye, 2 cylindrical, 3 equirectangular.
layout(location = 21) uniform int base_kind;
// perspective: tangents (left, right, top, bottom); fisheye: (half field of view in radians);
// cylindrical: (a0, a1 in radians, tan top, tan bottom); equirectangular: (a0, a1, e top,
// e bottom), all in radians.
layout(location = 22) uniform vec4 base_params;
layout(location = 23) uniform vec2 output_size;  // W, H in pixels
// Azimuth bases: one full turn in units of s (2π / |a1 - a0|); 0 for the others.
layout(location = 24) uniform float s_period;
// True when s = 0 and s = 1 are the same azimuth (a full 360° panorama).
layout(location = 25) uniform bool wraps_horizontally;

// The node grid: texel (i, j) holds node (i, j)'s offset (dx, dy) in output pixels and its
// coverage A. Read with texelFetch and interpolated here in float: hardware bilinear filtering
// weights have only 8 fractional bits, about 1/256 of a cell.
layout(binding = 1) uniform sampler2D node_offsets;

// s of azimuth alpha: on the branch nearest s_hint when use_hint, else FORMATS.md's rule
// (inside [0,1] when possible, else the branch nearest to it), as BaseProjection does.
float s_from_azimuth(float alpha, float s_hint, bool use_hint) {
  float s = (alpha - base_params.x) / (base_params.y - base_params.x);
  if (use_hint) {
    s += s_period * round((s_hint - s) / s_period);
  } else {
    s -= s_period * floor(s / s_period);
    if (s > 1.0 && (s_period - s) < (s - 1.0)) s -= s_period;
  }
  return s;
}

// Base coordinates (s, t) of an eye-frame point, and 1 in z where the base has a value there,
// else 0: behind a perspective image plane, on a cylinder's axis, straight behind a fisheye,
// or the eye point itself. At an equirectangular pole, s is the hint's (or 0.5).
vec3 st_from_eye(vec3 p_eye, float s_hint, bool use_hint) {
  vec3 b = R_base_eye * p_eye;
  float len = length(b);
  if (!(len > 0.0)) return vec3(0.0);
  b /= len;
  if (base_kind == 0) {
    if (!(b.z < 0.0)) return vec3(0.0);
    vec2 tan_xy = b.xy / -b.z;
    return vec3((tan_xy.x - base_params.x) / (base_params.y - base_params.x),
                (tan_xy.y - base_params.z) / (base_params.w - base_params.z), 1.0);
  }
  if (base_kind == 1) {
    float r = length(b.xy);
    if (r == 0.0) return b.z < 0.0 ? vec3(0.5, 0.5, 1.0) : vec3(0.0);
    float rho = atan(r, -b.z) / base_params.x;
    vec2 uv = rho * (b.xy / r);
    return vec3(0.5 * (uv.x + 1.0), 0.5 * (1.0 - uv.y), 1.0);
  }
  float horizontal = length(b.xz);
  if (base_kind == 2) {
    if (!(horizontal > 0.0)) return vec3(0.0);
    float s = s_from_azimuth(atan(b.x, -b.z), s_hint, use_hint);
    float y = b.y / horizontal;
    return vec3(s, (y - base_params.z) / (base_params.w - base_params.z), 1.0);
  }
  float e = atan(b.y, horizontal);
  float s = horizontal > 0.0 ? s_from_azimuth(atan(b.x, -b.z), s_hint, use_hint)
                             : (use_hint ? s_hint : 0.5);
  return vec3(s, (e - base_params.z) / (base_params.w - base_params.z), 1.0);
}

// Bilinear (dx, dy, A) at st, st clamped to [0,1]² (Warp::offset_at, Warp::coverage_at).
vec3 node_value(vec2 st) {
  ivec2 nodes = textureSize(node_offsets, 0);
  vec2 x = clamp(st, 0.0, 1.0) * vec2(nodes - 1);
  ivec2 i = min(ivec2(x), nodes - 2);
  vec2 f = x - vec2(i);
  vec3 o00 = texelFetch(node_offsets, i, 0).xyz;
  vec3 o10 = texelFetch(node_offsets, i + ivec2(1, 0), 0).xyz;
  vec3 o01 = texelFetch(node_offsets, i + ivec2(0, 1), 0).xyz;
  vec3 o11 = texelFetch(node_offsets, i + ivec2(1, 1), 0).xyz;
  return mix(mix(o00, o10, f.x), mix(o01, o11, f.x), f.y);
}

// Output pixel of st (Warp::q_from_st). On a wrapping base an s outside [0,1] is the same
// direction one turn away: its pixel is that of s mod 1 moved by whole output widths, so a
// triangle across the seam keeps its shape and lies partly beyond the image's left or right edge.
vec2 q_from_st(vec2 st) {
  float turns = wraps_horizontally ? floor(st.x) : 0.0;
  vec2 st_in = vec2(st.x - turns, st.y);
  return st_in * output_size + node_value(st_in).xy + vec2(turns * output_size.x, 0.0);
}

// Output pixel and validity (z) of an eye-frame point, on the branch nearest s_hint.
vec3 q_from_eye(vec3 p_eye, float s_hint, bool use_hint) {
  vec3 st = st_from_eye(p_eye, s_hint, use_hint);
  return vec3(q_from_st(st.xy), st.z);
}


// Back faces: counter-clockwise seen from the eye (at the origin) is the front, as the reference
// ray cast decides it. Decided in 3D, not from the projected winding, which a large triangle's
// straight projected edges can get wrong.
bool faces_eye(vec3 p0, vec3 p1, vec3 p2) { return dot(cross(p1 - p0, p2 - p0), p0) < 0.0; }

// True when the ray from the eye along base-frame direction d_base passes through the triangle
// (eye-frame points): d lies in the cone the three vertices span from the eye.
bool ray_pierces(vec3 d_base, vec3 p0, vec3 p1, vec3 p2) {
  vec3 d = transpose(R_base_eye) * d_base;
  float a = dot(d, cross(p0, p1)), b = dot(d, cross(p1, p2)), c = dot(d, cross(p2, p0));
  bool inside = (a >= 0.0 && b >= 0.0 && c >= 0.0) || (a <= 0.0 && b <= 0.0 && c <= 0.0);
  // In the cone and not in the opposite one: d on the triangle's side of the eye.
  return inside && dot(d, p0 + p1 + p2) > 0.0;
}

// True when the triangle surrounds a direction where P is singular: its image is not the inside
// of its projected vertices (it wraps round a point at infinity or the rim), so it cannot be
// drawn as one straight-edged triangle. Straight behind a fisheye; straight up or down for the
// azimuth bases (around the cylinder's axis, or an equirectangular pole). A perspective base's
// singular plane needs no test: a triangle with all three vertices in front lies wholly in front.
bool surrounds_singularity(vec3 p0, vec3 p1, vec3 p2) {
  if (base_kind == 1) return ray_pierces(vec3(0.0, 0.0, 1.0), p0, p1, p2);
  if (base_kind >= 2) {
    return ray_pierces(vec3(0.0, 1.0, 0.0), p0, p1, p2) ||
           ray_pierces(vec3(0.0, -1.0, 0.0), p0, p1, p2);
  }
  return false;
}

// Fisheye: largest ρ = |(2s − 1, 1 − 2t)| a vertex may have (set by the method halfway between
// the output's corners and the singular ρ straight behind). Cylindrical: t is kept within
// [−1, 2], up to three times the output's elevation-tangent span. Others: no limit.
layout(location = 30) uniform float fisheye_rho_limit;

// True when st lies so near a singular direction that a straight edge to it is meaningless:
// approaching straight behind a fisheye, two directions close to each other project to opposite
// sides of the rim, and the chord between them crosses the whole output.
bool beyond_guard(vec2 st) {
  if (base_kind == 1) return length(vec2(2.0 * st.x - 1.0, 1.0 - 2.0 * st.y)) > fisheye_rho_limit;
  if (base_kind == 2) return st.y < -1.0 || st.y > 2.0;
  return false;
}
