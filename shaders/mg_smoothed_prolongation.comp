#version 450
// The smoothed-aggregation prolongation P = Z - omega D^-1 K Z of one multigrid level
// (compute::BlockMultigrid's, on the device: vk::SmoothedTransfer). KZ arrives on P's
// pattern, which is block-complete: the b rows of a block store the same columns, so row
// b i + q's entry for a column sits at the same offset from its row's start as row r's.
// D^-1 is the level's block-Jacobi inverses (row r of its block at inverses[r b ..]);
// omega = 4 / (3 lambda) with lambda = ||v_k|| / ||v_k-1||, the power iteration's last two
// squared norms in scalars[0] (v_k-1) and scalars[1] (v_k). Z's entry of row b i + k is
// column b aggregates[i] + k. The level's smoother is written alongside: the inverses
// damped by min(maxDamping, spectralBound / lambda) (BlockMultigridSettings::
// smootherSpectralBound: the symmetric cycle stays positive definite).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer KZ { double kz[]; };
layout(std430, binding = 3) readonly buffer Inverses { double inverses[]; };
layout(std430, binding = 4) readonly buffer Aggregates { int aggregates[]; };
layout(std430, binding = 5) readonly buffer Scalars { double scalars[]; };
layout(std430, binding = 6) writeonly buffer Values { double values[]; };
layout(std430, binding = 7) writeonly buffer Smoother { double smoother[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint b;
  double maxDamping;
  double spectralBound;
} pc;

void main() {
  const double lambda = sqrt(scalars[1] / scalars[0]);
  precise double omega = 4.0 / (3.0 * lambda);
  const double damping = min(pc.maxDamping, pc.spectralBound / lambda);
  GRID_STRIDE_LOOP(r, pc.rows) {
    const uint i = r / pc.b, k = r % pc.b;
    const int begin = rowOffsets[r];
    for (uint q = 0; q < pc.b; ++q) smoother[r * pc.b + q] = damping * inverses[r * pc.b + q];
    const int identityColumn = aggregates[i] * int(pc.b) + int(k);
    for (int e = begin; e < rowOffsets[r + 1]; ++e) {
      precise double smoothed = 0.0;
      for (uint q = 0; q < pc.b; ++q) {
        smoothed += inverses[r * pc.b + q] * kz[rowOffsets[i * pc.b + q] + (e - begin)];
      }
      precise double value = (columns[e] == identityColumn ? 1.0 : 0.0) - omega * smoothed;
      values[e] = value;
    }
  }
}
