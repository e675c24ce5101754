// Test geometry: 2D positions in normalised device coordinates with a per-vertex colour.
layout(location = 0) in vec2 p_ndc;
layout(location = 1) in vec4 colour;

out vec4 v_colour;

void main() {
  v_colour = colour;
  gl_Position = vec4(p_ndc, 0.0, 1.0);
}
