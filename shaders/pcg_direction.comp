#version 450
// PCG search direction for m right-hand sides: P = Z + beta P with
// beta = (r.z)_new / (r.z)_old per column, read from the device's scalars.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Z { double z[]; };
layout(std430, binding = 1) buffer P { double p[]; };
layout(std430, binding = 2) readonly buffer Scalars { double scalars[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint slotNew;
  uint slotOld;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) {
    const uint column = i / pc.n;
    const double old = scalars[pc.slotOld * pc.m + column];
    const double beta = old != 0.0 ? scalars[pc.slotNew * pc.m + column] / old : 0.0;
    p[i] = z[i] + beta * p[i];
  }
}
