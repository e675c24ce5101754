// Baselines: scene vertex pulling shared by the cube-map faces and the per-vertex projection.
// Not a program of its own: linked as a second vertex shader object. Bindings are GpuScene's
// (GpuScene::bind_for_pulling): uint32 indices, vertices as buffer textures.
layout(std430, binding = 3) readonly buffer Indices { uint indices[]; };
layout(binding = 8) uniform samplerBuffer position_texels;  // RGB32F, metres, object frame
layout(binding = 9) uniform samplerBuffer normal_texels;    // RGB32F
layout(binding = 10) uniform samplerBuffer uv_texels;       // RG32F

// The draw's primitive: its first index in the scene's indices.
layout(location = 2) uniform uint first_index;

uint pulled_vertex() { return indices[first_index + uint(gl_VertexID)]; }
vec3 pulled_position(uint v) { return texelFetch(position_texels, int(v)).xyz; }
vec3 pulled_normal(uint v) { return texelFetch(normal_texels, int(v)).xyz; }
vec2 pulled_uv(uint v) { return texelFetch(uv_texels, int(v)).xy; }
