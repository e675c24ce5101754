// A procedural texture in the world frame: marble, veins of a sine of x + z turbulence from
// value noise at four octaves, multiplied with the base colour and lit. It depends only on the
// world position, so it stays put on a moving view and across facet seams. Octaves finer than
// two output pixels are faded out (their size from the position's screen gradient).
float hash(vec3 p) {
  p = fract(p * 0.3183099 + 0.1);
  p *= 17.0;
  return fract(p.x * p.y * p.z * (p.x + p.y + p.z));
}

float value_noise(vec3 x) {
  vec3 i = floor(x), f = fract(x);
  vec3 u = f * f * (3.0 - 2.0 * f);
  return mix(mix(mix(hash(i), hash(i + vec3(1, 0, 0)), u.x),
                 mix(hash(i + vec3(0, 1, 0)), hash(i + vec3(1, 1, 0)), u.x), u.y),
             mix(mix(hash(i + vec3(0, 0, 1)), hash(i + vec3(1, 0, 1)), u.x),
                 mix(hash(i + vec3(0, 1, 1)), hash(i + vec3(1, 1, 1)), u.x), u.y),
             u.z);
}

vec4 shade(MaterialInput m) {
  const float kScale = 0.5;  // noise cells per metre at the first octave
  vec3 p = m.p_world * kScale;
  float metres_per_px = length(fwidth(m.p_world));
  float turbulence = 0.0, amplitude = 1.0, frequency = 1.0;
  for (int octave = 0; octave < 4; ++octave) {
    float cell_px = 1.0 / max(frequency * kScale * metres_per_px, 1e-6);
    float keep = clamp(cell_px / 2.0 - 1.0, 0.0, 1.0);
    turbulence += keep * amplitude * abs(value_noise(p * frequency) * 2.0 - 1.0);
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  float vein = 0.5 + 0.5 * sin(3.0 * (p.x + p.z) + 6.0 * turbulence);
  vec3 marble = mix(vec3(0.35, 0.33, 0.36), vec3(0.95, 0.93, 0.9), pow(vein, 0.4));
  return vec4(sun_and_sky(m) * marble, m.base_colour.a);
}
