#version 450
// The ADMM z and y updates over the m x k constraint rows (OSQP Algorithm 1, steps 4-6):
//   zR = alpha zTilde + (1 - alpha) z
//   zNext = clamp(zR + y / rho, l, u),  y += rho (zR - zNext),  z = zNext
// with rho per row; when `saveDual` is set, y is first copied to yPrevious (the dual step
// of the infeasibility certificate). One fused pass instead of five vector operations.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer ZTilde { double zTilde[]; };
layout(std430, binding = 1) buffer Z { double z[]; };
layout(std430, binding = 2) buffer Y { double y[]; };
layout(std430, binding = 3) writeonly buffer YPrevious { double yPrevious[]; };
layout(std430, binding = 4) readonly buffer Lower { double lower[]; };
layout(std430, binding = 5) readonly buffer Upper { double upper[]; };
layout(std430, binding = 6) readonly buffer Rho { double rho[]; };

layout(push_constant) uniform Push {
  uint m;
  uint count;  // m * k
  uint saveDual;
  uint pad;
  double alpha;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) {
    const double r = rho[i % pc.m];
    const double yi = y[i];
    precise double zRelaxed = pc.alpha * zTilde[i] + (1.0 - pc.alpha) * z[i];
    precise double shifted = zRelaxed + (1.0 / r) * yi;
    const double zNext = min(max(shifted, lower[i]), upper[i]);
    precise double yNext = yi + r * (zRelaxed - zNext);
    if (pc.saveDual != 0) yPrevious[i] = yi;
    y[i] = yNext;
    z[i] = zNext;
  }
}
