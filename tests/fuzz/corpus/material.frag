vec4 shade(MaterialInput m) {
  float light = max(dot(m.n_world, vec3(0.0, 0.0, 1.0)), 0.2);
  return vec4(m.base_colour.rgb * light, m.base_colour.a);
}
