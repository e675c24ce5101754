// Baselines: scene vertex pulling shared by the cube-map faces and the per-vertex projection.
// Not a program of its own: linked as a second vertex shader object. Bindings are GpuScene's
// buffers: tightly packed floats and uint32 indices.
layout(std430, binding = 0) readonly buffer Positions { float positions[]; };
layout(std430, binding = 1) readonly buffer Normals { float normals[]; };
layout(std430, binding = 2) readonly buffer Uvs { float uvs[]; };
layout(std430, binding = 3) readonly buffer Indices { uint indices[]; };

// The draw's primitive: its first index in Indices.
layout(location = 2) uniform uint first_index;

uint pulled_vertex() { return indices[first_index + uint(gl_VertexID)]; }
vec3 pulled_position(uint v) {
  return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}
vec3 pulled_normal(uint v) {
  return vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
}
vec2 pulled_uv(uint v) { return vec2(uvs[2u * v], uvs[2u * v + 1u]); }
