#version 450
// First pass of the support term of the infeasibility certificate, per column:
// sum_i u_i max(dy_i, 0) + l_i min(dy_i, 0) (m x k, column-major); partial sums per
// workgroup as in la_dot, finished by la_reduce.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer DY { double dy[]; };
layout(std430, binding = 1) readonly buffer Lower { double lower[]; };
layout(std430, binding = 2) readonly buffer Upper { double upper[]; };
layout(std430, binding = 3) writeonly buffer Partial { double partial[]; };

layout(push_constant) uniform Push {
  uint n;
} pc;

shared double sums[PLANO_GROUP_SIZE];

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint base = column * pc.n;
  double sum = 0.0;
  GRID_STRIDE_LOOP(i, pc.n) {
    const double d = dy[base + i];
    precise double term = upper[base + i] * max(d, 0.0) + lower[base + i] * min(d, 0.0);
    sum += term;
  }
  const uint lane = gl_LocalInvocationID.x;
  sums[lane] = sum;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) sums[lane] += sums[lane + width];
    barrier();
  }
  if (lane == 0) partial[column * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
}
