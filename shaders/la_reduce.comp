#version 450
// Second pass of the dot products: one workgroup per column sums its `groups` partial
// sums and writes scalars[slot * m + column].
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Partial { double partial[]; };
layout(std430, binding = 1) buffer Scalars { double scalars[]; };

layout(push_constant) uniform Push {
  uint groups;  // partial sums per column
  uint m;       // columns
  uint slot;
} pc;

shared double sums[PLANO_GROUP_SIZE];

void main() {
  const uint column = gl_WorkGroupID.x;
  const uint lane = gl_LocalInvocationID.x;
  double sum = 0.0;
  for (uint g = lane; g < pc.groups; g += PLANO_GROUP_SIZE) sum += partial[column * pc.groups + g];
  sums[lane] = sum;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) sums[lane] += sums[lane + width];
    barrier();
  }
  if (lane == 0) scalars[pc.slot * pc.m + column] = sums[0];
}
