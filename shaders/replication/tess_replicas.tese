// Tessellator form, evaluation stage: passes each generated vertex's (u, v) and the patch's
// replica table on to the geometry stage, which turns every line segment into one replica.
layout(isolines, equal_spacing) in;

patch in uvec4 tc_replicas;
out vec2 te_uv;
flat out uvec4 te_replicas;

void main() {
  te_uv = gl_TessCoord.xy;
  te_replicas = tc_replicas;
  gl_Position = vec4(0.0);
}
