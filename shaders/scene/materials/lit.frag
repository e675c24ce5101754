// The default material: base colour times texture under a fixed sun and sky, or as authored for
// unlit scene materials.
vec4 shade(MaterialInput m) { return vec4(sun_and_sky(m), m.base_colour.a); }
