#version 450
// Fused PCG product: Q = A P for m columns and, in the same pass, the first-pass partial
// sums of p.q per workgroup (finished by la_reduce), saving a re-read of P and Q.
// Dispatch: the dot products' fixed workgroup count in x, one row of groups per column.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer P { double p[]; };
layout(std430, binding = 4) writeonly buffer Q { double q[]; };
layout(std430, binding = 5) writeonly buffer Partial { double partial[]; };

layout(push_constant) uniform Push {
  uint n;
} pc;

shared double sums[PLANO_GROUP_SIZE];

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint base = column * pc.n;
  double pq = 0.0;
  GRID_STRIDE_LOOP(r, pc.n) {
    double sum = 0.0;
    const int end = rowOffsets[r + 1];
    for (int e = rowOffsets[r]; e < end; ++e) sum += values[e] * p[base + uint(columns[e])];
    q[base + r] = sum;
    pq += p[base + r] * sum;
  }
  const uint lane = gl_LocalInvocationID.x;
  sums[lane] = pq;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) sums[lane] += sums[lane + width];
    barrier();
  }
  if (lane == 0) partial[column * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
}
