#version 450
// C = A B^T on C's fixed pattern, for CSR matrices whose patterns are block-complete in
// b x b blocks (b <= 4: the b rows of a block store the same columns, in whole blocks),
// with sorted columns. One invocation per block (I, J) of C: it merges block row I of A
// with block row J of B by their block columns and adds A_IK B_JK^T for each block K the
// two share. Against a merge per scalar entry (each scalar row b times as long, and b^2
// entries per block), the merges walk 16x fewer column indices for b = 4, and each match
// is a small dense product. The Galerkin product of the smoothed-aggregation multigrid
// (vk::SmoothedTransfer) is two of these: W = P^T K and P^T K P = P^T W^T, K being
// symmetric.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer AOffsets { int aOffsets[]; };
layout(std430, binding = 1) readonly buffer AColumns { int aColumns[]; };
layout(std430, binding = 2) readonly buffer AValues { double aValues[]; };
layout(std430, binding = 3) readonly buffer BOffsets { int bOffsets[]; };
layout(std430, binding = 4) readonly buffer BColumns { int bColumns[]; };
layout(std430, binding = 5) readonly buffer BValues { double bValues[]; };
layout(std430, binding = 6) readonly buffer COffsets { int cOffsets[]; };
layout(std430, binding = 7) readonly buffer CColumns { int cColumns[]; };
layout(std430, binding = 8) writeonly buffer CValues { double cValues[]; };
// Per block of C: its block row I and the position of its first entry in row b I.
layout(std430, binding = 9) readonly buffer Blocks { ivec2 blocks[]; };

layout(push_constant) uniform Push {
  uint blockCount;
  uint b;
} pc;

void main() {
  const int b = int(pc.b);
  GRID_STRIDE_LOOP(e, pc.blockCount) {
    const int I = blocks[e].x, first = blocks[e].y;
    const int J = cColumns[first] / b;
    const int aRow = b * I, bRow = b * J;
    int a = aOffsets[aRow];
    const int aStart = a, aEnd = aOffsets[aRow + 1];
    int c = bOffsets[bRow];
    const int bStart = c, bEnd = bOffsets[bRow + 1];
    double sum[16];
    for (int t = 0; t < 16; ++t) sum[t] = 0.0;
    while (a < aEnd && c < bEnd) {
      const int aBlock = aColumns[a] / b, bBlock = bColumns[c] / b;
      if (aBlock == bBlock) {
        for (int q = 0; q < b; ++q) {
          const int aAt = aOffsets[aRow + q] + (a - aStart);
          for (int r = 0; r < b; ++r) {
            const int bAt = bOffsets[bRow + r] + (c - bStart);
            precise double s = sum[q * 4 + r];
            for (int k = 0; k < b; ++k) s += aValues[aAt + k] * bValues[bAt + k];
            sum[q * 4 + r] = s;
          }
        }
        a += b;
        c += b;
      } else if (aBlock < bBlock) {
        a += b;
      } else {
        c += b;
      }
    }
    for (int q = 0; q < b; ++q) {
      const int at = cOffsets[aRow + q] + (first - cOffsets[aRow]);
      for (int r = 0; r < b; ++r) cValues[at + r] = sum[q * 4 + r];
    }
  }
}
