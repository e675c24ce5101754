// Writes values[i] = i * i + offset for every i < count: a check that compute shaders, SSBOs and
// uniforms work.
layout(local_size_x = 64) in;

layout(std430, binding = 0) writeonly buffer Values {
  uint values[];
};

layout(location = 0) uniform uint count;
layout(location = 1) uniform uint offset;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  values[i] = i * i + offset;
}
