#version 450
// One PCG update for m right-hand sides (n x m column-major), with the step length
// alpha = (r.z) / (p.q) of each column read from the device's scalars, so that no scalar
// travels to the host: X += alpha P, R -= alpha Q, Z = M^-1 R with the block-Jacobi
// preconditioner (n / b dense b x b inverse blocks, row-major; b = 1: Jacobi), and in the
// same pass the first-pass partial sums of the new r.z (finished by la_reduce) and, when
// asked, of r.r after them (partial sums of column c's r.r at column m + c, so that one
// la_reduce over 2m columns writes r.r into the slot after r.z's).
// Dispatch: the dot products' fixed workgroup count in x, one row of groups per column.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer P { double p[]; };
layout(std430, binding = 1) readonly buffer Q { double q[]; };
layout(std430, binding = 2) buffer X { double x[]; };
layout(std430, binding = 3) buffer R { double r[]; };
layout(std430, binding = 4) writeonly buffer Z { double z[]; };
layout(std430, binding = 5) readonly buffer InverseBlocks { double inverseBlocks[]; };
layout(std430, binding = 6) readonly buffer Scalars { double scalars[]; };
layout(std430, binding = 7) writeonly buffer Partial { double partial[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint slotRz;  // r.z of the current iterate
  uint slotPq;  // p.q
  uint b;       // preconditioner block size; divides n, at most MAX_BLOCK
  uint residualNorms;  // 1: also the partial sums of r.r
} pc;

#define MAX_BLOCK 4

shared double sums[PLANO_GROUP_SIZE];
shared double squares[PLANO_GROUP_SIZE];

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint base = column * pc.n;
  const double pq = scalars[pc.slotPq * pc.m + column];
  // A converged column (r = 0) gives p.q = 0: stand still instead of dividing by zero.
  const double alpha = pq != 0.0 ? scalars[pc.slotRz * pc.m + column] / pq : 0.0;
  double rz = 0.0, rr = 0.0;
  GRID_STRIDE_LOOP(block, pc.n / pc.b) {
    const uint first = base + block * pc.b;
    double residual[MAX_BLOCK];
    for (uint t = 0; t < pc.b; ++t) {
      x[first + t] += alpha * p[first + t];
      residual[t] = r[first + t] - alpha * q[first + t];
      r[first + t] = residual[t];
    }
    const uint entries = block * pc.b * pc.b;
    for (uint t = 0; t < pc.b; ++t) {
      double zi = 0.0;
      for (uint u = 0; u < pc.b; ++u) zi += inverseBlocks[entries + t * pc.b + u] * residual[u];
      z[first + t] = zi;
      rz += residual[t] * zi;
      rr += residual[t] * residual[t];
    }
  }
  const uint lane = gl_LocalInvocationID.x;
  sums[lane] = rz;
  squares[lane] = rr;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) {
      sums[lane] += sums[lane + width];
      squares[lane] += squares[lane + width];
    }
    barrier();
  }
  if (lane == 0) {
    partial[column * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
    if (pc.residualNorms != 0) partial[(pc.m + column) * gl_NumWorkGroups.x + gl_WorkGroupID.x] = squares[0];
  }
}
