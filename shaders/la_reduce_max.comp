#version 450
// Second pass of the inf-norms (la_max_abs): one workgroup per column takes the max of
// its `groups` partial maxima (NaN sticky) and writes scalars[slot * m + column].
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Partial { double partial[]; };
layout(std430, binding = 1) buffer Scalars { double scalars[]; };

layout(push_constant) uniform Push {
  uint groups;  // partial maxima per column
  uint m;       // columns
  uint slot;
} pc;

shared double maxima[PLANO_GROUP_SIZE];

double stickyMax(double m, double v) { return (v > m || isnan(v)) && !isnan(m) ? v : m; }

void main() {
  const uint column = gl_WorkGroupID.x;
  const uint lane = gl_LocalInvocationID.x;
  double m = 0.0;
  for (uint g = lane; g < pc.groups; g += PLANO_GROUP_SIZE) m = stickyMax(m, partial[column * pc.groups + g]);
  maxima[lane] = m;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) maxima[lane] = stickyMax(maxima[lane], maxima[lane + width]);
    barrier();
  }
  if (lane == 0) scalars[pc.slot * pc.m + column] = maxima[0];
}
