// Content through the exact warp (mode 2): every output pixel takes its exact eye direction from
// the lookup texture (computed on the CPU through the warp inverse), maps it into the content
// image as projection/content_projection.hpp does, and samples the content in linear light
// (sRGB textures decode before filtering). Where a source texel covers more than an output pixel
// the sample is bicubic (Catmull-Rom, clamped to its 2×2 neighbours, so no ringing); where the
// source is finer than the output it is trilinear over the mip levels and anisotropic, with the
// taps spread here rather than by the sampler (llvmpipe's GL_EXT_texture_filter_anisotropic
// returns stray texels). Texel footprints come from the neighbouring pixels' directions, not from
// screen-space derivatives, so the edges of the coverage and the panorama's seam stay sharp.
layout(binding = 0) uniform sampler2D lookup;  // RGBA32F: eye direction xyz, w = 1 if covered
layout(binding = 1) uniform sampler2D content_2d;
layout(binding = 2) uniform samplerCube content_cube;

layout(location = 0) uniform mat3 R_content_eye;
layout(location = 1) uniform int content_format;  // ContentFormat: see below
// fisheye: x = 2 / field of view in radians; perspective: tangents left, right, top, bottom.
layout(location = 2) uniform vec4 content_params;
layout(location = 3) uniform int bicubic_when_magnifying;
// Trilinear taps along the footprint's major axis at most (1: isotropic trilinear).
layout(location = 4) uniform int max_anisotropy;

layout(location = 0) out vec4 out_colour;

const int FISHEYE = 0;
const int EQUIRECT = 1;
const int CUBEMAP = 2;
const int PERSPECTIVE = 3;
const float PI = 3.14159265358979;

// Content-frame direction b to image coordinates st (s right, t down); false where the content
// has no value.
bool st_of(vec3 b, out vec2 st) {
  st = vec2(0.0);
  if (content_format == FISHEYE) {
    // The dome master's frame: its view axis is the zenith, its image up the dome's back (+z).
    vec3 f = vec3(b.x, b.z, -b.y);
    float radial = length(f.xy);
    float rho = atan(radial, -f.z) * content_params.x;
    if (rho > 1.0) return false;
    vec2 uv = radial > 0.0 ? f.xy * (rho / radial) : vec2(0.0);
    st = vec2(0.5 + 0.5 * uv.x, 0.5 - 0.5 * uv.y);
    return true;
  }
  if (content_format == EQUIRECT) {
    float azimuth = atan(b.x, -b.z);
    float elevation = atan(b.y, length(b.xz));
    st = vec2(azimuth / (2.0 * PI) + 0.5, 0.5 - elevation / PI);
    return true;
  }
  // PERSPECTIVE
  if (!(b.z < 0.0)) return false;
  vec2 tangent = b.xy / -b.z;
  st = (tangent - content_params.xz) / (content_params.yw - content_params.xz);
  return all(greaterThanEqual(st, vec2(0.0))) && all(lessThanEqual(st, vec2(1.0)));
}

// The content-frame direction of pixel p, false where the warp does not cover it.
bool direction_at(ivec2 p, out vec3 b) {
  b = vec3(0.0);
  ivec2 size = textureSize(lookup, 0);
  if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, size))) return false;
  vec4 v_eye = texelFetch(lookup, p, 0);
  b = R_content_eye * v_eye.xyz;
  return v_eye.w >= 0.5;
}

// d st / d pixel along `step`: from the next pixel, or the previous one at an edge; zero where
// neither has content. A panorama's seam is crossed the short way.
vec2 st_step(ivec2 p, ivec2 step, vec2 st) {
  vec3 b;
  vec2 other;
  if (direction_at(p + step, b) && st_of(b, other)) {
    vec2 d = other - st;
    if (content_format == EQUIRECT) d.x -= round(d.x);
    return d;
  }
  if (direction_at(p - step, b) && st_of(b, other)) {
    vec2 d = st - other;
    if (content_format == EQUIRECT) d.x -= round(d.x);
    return d;
  }
  return vec2(0.0);
}

vec3 direction_step(ivec2 p, ivec2 step, vec3 b) {
  vec3 other;
  if (direction_at(p + step, other)) return other - b;
  if (direction_at(p - step, other)) return b - other;
  return vec3(0.0);
}

ivec2 texel_index(ivec2 i, ivec2 size) {
  if (content_format == EQUIRECT) i.x = ((i.x % size.x) + size.x) % size.x;
  return clamp(i, ivec2(0), size - 1);
}

vec4 catmull_rom_weights(float t) {
  return vec4(t * (-0.5 + t * (1.0 - 0.5 * t)), 1.0 + t * t * (-2.5 + 1.5 * t),
              t * (0.5 + t * (2.0 - 1.5 * t)), t * t * (-0.5 + 0.5 * t));
}

vec4 bicubic(vec2 st) {
  ivec2 size = textureSize(content_2d, 0);
  vec2 p = st * vec2(size) - 0.5;
  vec2 p0 = floor(p);
  vec2 f = p - p0;
  ivec2 i0 = ivec2(p0);
  vec4 wx = catmull_rom_weights(f.x), wy = catmull_rom_weights(f.y);
  vec4 sum = vec4(0.0);
  vec4 low = vec4(1e30), high = vec4(-1e30);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      vec4 texel = texelFetch(content_2d, texel_index(i0 + ivec2(i - 1, j - 1), size), 0);
      sum += wx[i] * wy[j] * texel;
      if (i == 1 || i == 2) {
        if (j == 1 || j == 2) {
          low = min(low, texel);
          high = max(high, texel);
        }
      }
    }
  }
  return clamp(sum, low, high);
}

// The number of trilinear taps for a footprint whose axes are `major` and `minor` long.
int tap_count(float major, float minor) {
  return int(clamp(ceil(major / max(minor, 1e-6)), 1.0, float(max_anisotropy)));
}

// Anisotropic filtering in the shader: trilinear taps spread along the footprint's major axis,
// each at the level of detail of the minor axis (or of major / taps when that is larger).
vec4 anisotropic_2d(vec2 st, vec2 dx, vec2 dy) {
  vec2 texels = vec2(textureSize(content_2d, 0));
  float lx = length(dx * texels), ly = length(dy * texels);
  vec2 major = lx >= ly ? dx : dy;
  vec2 minor = lx >= ly ? dy : dx;
  int n = tap_count(max(lx, ly), min(lx, ly));
  vec4 sum = vec4(0.0);
  for (int i = 0; i < n; ++i) {
    float offset = (float(i) + 0.5) / float(n) - 0.5;
    sum += textureGrad(content_2d, st + major * offset, major / float(n), minor);
  }
  return sum / float(n);
}

vec4 anisotropic_cube(vec3 b, vec3 dx, vec3 dy) {
  float lx = length(dx), ly = length(dy);
  vec3 major = lx >= ly ? dx : dy;
  vec3 minor = lx >= ly ? dy : dx;
  int n = tap_count(max(lx, ly), min(lx, ly));
  vec4 sum = vec4(0.0);
  for (int i = 0; i < n; ++i) {
    float offset = (float(i) + 0.5) / float(n) - 0.5;
    sum += textureGrad(content_cube, b + major * offset, major / float(n), minor);
  }
  return sum / float(n);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 b;
  if (!direction_at(p, b)) discard;
  vec4 colour = vec4(0.0, 0.0, 0.0, 1.0);
  if (content_format == CUBEMAP) {
    colour = anisotropic_cube(b, direction_step(p, ivec2(1, 0), b),
                              direction_step(p, ivec2(0, 1), b));
  } else {
    vec2 st;
    if (st_of(b, st)) {
      vec2 dst_dx = st_step(p, ivec2(1, 0), st), dst_dy = st_step(p, ivec2(0, 1), st);
      vec2 texels = vec2(textureSize(content_2d, 0));
      float footprint = max(length(dst_dx * texels), length(dst_dy * texels));
      if (bicubic_when_magnifying != 0 && footprint <= 1.0)
        colour = bicubic(st);
      else
        colour = anisotropic_2d(st, dst_dx, dst_dy);
    }
  }
  out_colour = vec4(colour.rgb, 1.0);
}
