#version 450
// K = K0 + rho K1 on one sparsity pattern (K0 = P + sigma I, K1 = C^T D C with D = 1 on
// inequality rows and equalityRhoScale on equality rows), and the Jacobi preconditioner
// 1 / diag(K): a rho update of the ADMM without a host refactorization.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer K0 { double k0[]; };
layout(std430, binding = 1) readonly buffer K1 { double k1[]; };
layout(std430, binding = 2) readonly buffer Diagonal { int diagonal[]; };  // index of (r, r)
layout(std430, binding = 3) writeonly buffer K { double k[]; };
layout(std430, binding = 4) writeonly buffer InverseDiagonal { double inverseDiagonal[]; };

layout(push_constant) uniform Push {
  uint nonZeros;
  uint n;
  double rho;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, max(pc.nonZeros, pc.n)) {
    if (i < pc.nonZeros) {
      precise double value = k0[i] + pc.rho * k1[i];
      k[i] = value;
    }
    if (i < pc.n) {
      const int e = diagonal[i];
      precise double d = k0[e] + pc.rho * k1[e];
      inverseDiagonal[i] = 1.0 / d;
    }
  }
}
