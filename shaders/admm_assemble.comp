#version 450
// K = K0 + rho K1 on one sparsity pattern (K0 = P + sigma I, K1 = C^T D C with D = 1 on
// inequality rows and equalityRhoScale on equality rows): a rho update of the ADMM
// without a host refactorization (the host inverts only the preconditioner's small blocks).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer K0 { double k0[]; };
layout(std430, binding = 1) readonly buffer K1 { double k1[]; };
layout(std430, binding = 2) writeonly buffer K { double k[]; };

layout(push_constant) uniform Push {
  uint nonZeros;
  uint pad;
  double rho;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.nonZeros) {
    precise double value = k0[i] + pc.rho * k1[i];
    k[i] = value;
  }
}
