#version 450
// First pass of the column-wise dot products of X and Y (n x m each): every workgroup
// writes the sum over its grid-stride share of one column to partial[column * groups +
// group]. A fixed-shape tree in shared memory, no atomics (float64 atomics are rare:
// lavapipe has none), so results are reproducible run to run. la_reduce finishes.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer X { double x[]; };
layout(std430, binding = 1) readonly buffer Y { double y[]; };
layout(std430, binding = 2) writeonly buffer Partial { double partial[]; };

layout(push_constant) uniform Push {
  uint n;
} pc;

shared double sums[PLANO_GROUP_SIZE];

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint base = column * pc.n;
  double sum = 0.0;
  GRID_STRIDE_LOOP(i, pc.n) { sum += x[base + i] * y[base + i]; }
  const uint lane = gl_LocalInvocationID.x;
  sums[lane] = sum;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) sums[lane] += sums[lane + width];
    barrier();
  }
  if (lane == 0) partial[column * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
}
