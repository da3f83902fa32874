#version 450
// One rho update of the ADMM on the device, no host data: K = K0 + rho K1 on one sparsity
// pattern (K0 = P + sigma I, K1 = C^T D C with D = 1 on inequality rows and
// equalityRhoScale on equality rows) and the per-row penalties rho D.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer K0 { double k0[]; };
layout(std430, binding = 1) readonly buffer K1 { double k1[]; };
layout(std430, binding = 2) writeonly buffer K { double k[]; };
layout(std430, binding = 3) readonly buffer RowScales { double rowScales[]; };
layout(std430, binding = 4) writeonly buffer RhoRows { double rhoRows[]; };

layout(push_constant) uniform Push {
  uint nonZeros;
  uint rows;
  double rho;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, max(pc.nonZeros, pc.rows)) {
    if (i < pc.nonZeros) {
      precise double value = k0[i] + pc.rho * k1[i];
      k[i] = value;
    }
    if (i < pc.rows) {
      precise double value = pc.rho * rowScales[i];
      rhoRows[i] = value;
    }
  }
}
