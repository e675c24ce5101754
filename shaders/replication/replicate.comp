// Seed pipeline, pass 2b: the replicated index. Triangle t with count c and offset o (exclusive
// scan) gets entries o..o+c-1 = (t, k) for its k-th facet; pass 3 finds that facet again.
layout(local_size_x = 64) in;

layout(std430, binding = 10) readonly buffer Scan { uint scan[]; };
layout(std430, binding = 11) writeonly buffer Pairs { uvec2 pairs[]; };
layout(location = 42) uniform uint triangle_count;

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t >= triangle_count) return;
  for (uint at = scan[t], k = 0u; at < scan[t + 1u]; ++at, ++k) pairs[at] = uvec2(t, k);
}
