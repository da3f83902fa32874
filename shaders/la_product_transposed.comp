#version 450
// C = A B^T on C's fixed pattern, for CSR matrices A and B with sorted columns: entry
// (r, c) is the dot product of A's row r with B's row c, a merge of their column lists.
// One invocation per entry of C (its row found by bisection of C's row offsets), so an
// invocation's loops stay short however long C's rows grow: a row per invocation looped
// past llvmpipe's 65 535 back-edges on dense coarse multigrid levels. The Galerkin product
// of the smoothed-aggregation multigrid (vk::SmoothedTransfer) is two of these: W = P^T K
// and P^T K P = P^T W^T, K being symmetric.
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

layout(push_constant) uniform Push {
  uint rows;     // C's rows
  uint entries;  // C's stored entries
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.entries) {
    // The row r with cOffsets[r] <= e < cOffsets[r + 1].
    uint low = 0, high = pc.rows;
    while (high - low > 1) {
      const uint middle = (low + high) / 2;
      if (uint(cOffsets[middle]) <= e) {
        low = middle;
      } else {
        high = middle;
      }
    }
    const int c = cColumns[e];
    int a = aOffsets[low];
    const int aEnd = aOffsets[low + 1];
    int b = bOffsets[c];
    const int bEnd = bOffsets[c + 1];
    precise double sum = 0.0;
    while (a < aEnd && b < bEnd) {
      const int aColumn = aColumns[a], bColumn = bColumns[b];
      if (aColumn == bColumn) {
        sum += aValues[a] * bValues[b];
        ++a;
        ++b;
      } else if (aColumn < bColumn) {
        ++a;
      } else {
        ++b;
      }
    }
    cValues[e] = sum;
  }
}
