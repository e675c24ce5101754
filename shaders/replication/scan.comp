// Exclusive prefix sum over data[0, element_count), in blocks of 4 * LOCAL_SIZE elements.
// Without SCAN_ADD: scans each block in place and writes the block's total to block_sums[block].
// With SCAN_ADD: adds block_sums[block] (already scanned) to every element of the block. The host
// recurses on block_sums until one block holds everything (driver/src/replication_common.cpp).
#ifndef LOCAL_SIZE
#define LOCAL_SIZE 256
#endif
#ifndef SCAN_ADD
#define SCAN_ADD 0
#endif
layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 10) buffer Data { uint data[]; };
layout(std430, binding = 15) buffer BlockSums { uint block_sums[]; };
layout(location = 0) uniform uint element_count;

shared uint partial[LOCAL_SIZE];

void main() {
  uint first = gl_WorkGroupID.x * 4u * LOCAL_SIZE + 4u * gl_LocalInvocationID.x;
#if SCAN_ADD
  uint add = block_sums[gl_WorkGroupID.x];
  for (uint i = first; i < min(first + 4u, element_count); ++i) data[i] += add;
#else
  uint v[4];
  uint sum = 0u;
  for (uint k = 0u; k < 4u; ++k) {
    uint i = first + k;
    v[k] = i < element_count ? data[i] : 0u;
    sum += v[k];
  }
  uint lid = gl_LocalInvocationID.x;
  partial[lid] = sum;
  barrier();
  // Hillis–Steele inclusive scan of the threads' sums.
  for (uint offset = 1u; offset < LOCAL_SIZE; offset *= 2u) {
    uint add = lid >= offset ? partial[lid - offset] : 0u;
    barrier();
    partial[lid] += add;
    barrier();
  }
  uint running = partial[lid] - sum;
  for (uint k = 0u; k < 4u; ++k) {
    uint i = first + k;
    if (i < element_count) data[i] = running;
    running += v[k];
  }
  if (lid == LOCAL_SIZE - 1u) block_sums[gl_WorkGroupID.x] = partial[lid];
#endif
}
