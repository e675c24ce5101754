// Writes the interpolated vertex colour, scaled by TEST_COLOUR_SCALE so that tests can check
// that caller defines reach the shader.
#ifndef TEST_COLOUR_SCALE
#define TEST_COLOUR_SCALE 1.0
#endif

in vec4 v_colour;
layout(location = 0) out vec4 out_colour;

void main() {
  out_colour = v_colour * TEST_COLOUR_SCALE;
}
