// Overlay text: triangles in window pixels from the top-left corner, pulled from a buffer.
layout(std430, binding = 0) readonly buffer Vertices {
  vec2 xy[];
};
layout(location = 0) uniform vec2 window_size;

void main() {
  vec2 ndc = xy[gl_VertexID] / window_size * 2.0 - 1.0;
  gl_Position = vec4(ndc.x, -ndc.y, 0.0, 1.0);
}
