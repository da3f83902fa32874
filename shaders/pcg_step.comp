#version 450
// One PCG update for m right-hand sides (n x m column-major), with the step length
// alpha = (r.z) / (p.q) of each column read from the device's scalars, so that no scalar
// travels to the host: X += alpha P, R -= alpha Q, Z = Dinv R (Jacobi preconditioner).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer P { double p[]; };
layout(std430, binding = 1) readonly buffer Q { double q[]; };
layout(std430, binding = 2) buffer X { double x[]; };
layout(std430, binding = 3) buffer R { double r[]; };
layout(std430, binding = 4) writeonly buffer Z { double z[]; };
layout(std430, binding = 5) readonly buffer InverseDiagonal { double inverseDiagonal[]; };
layout(std430, binding = 6) readonly buffer Scalars { double scalars[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint slotRz;  // r.z of the current iterate
  uint slotPq;  // p.q
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) {
    const uint column = i / pc.n;
    const double pq = scalars[pc.slotPq * pc.m + column];
    // A converged column (r = 0) gives p.q = 0: stand still instead of dividing by zero.
    const double alpha = pq != 0.0 ? scalars[pc.slotRz * pc.m + column] / pq : 0.0;
    x[i] += alpha * p[i];
    const double ri = r[i] - alpha * q[i];
    r[i] = ri;
    z[i] = inverseDiagonal[i - column * pc.n] * ri;
  }
}
