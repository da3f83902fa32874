#version 450
// The multigrid's coarsest level as a dense row-major matrix, K_c = K0_c + rho K1_c, from
// the values of both on the coarsest level's sparsity pattern (CSR), ready for its
// in-place inversion (mg_coarsest_invert). One invocation per row writes the whole row.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Offsets { int offsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer K0 { double k0[]; };
layout(std430, binding = 3) readonly buffer K1 { double k1[]; };
layout(std430, binding = 4) writeonly buffer Dense { double dense[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint pad;
  double rho;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.rows) {
    for (uint j = 0; j < pc.rows; ++j) dense[i * pc.rows + j] = 0.0;
    for (int e = offsets[i]; e < offsets[i + 1]; ++e) dense[i * pc.rows + uint(columns[e])] = k0[e] + pc.rho * k1[e];
  }
}
