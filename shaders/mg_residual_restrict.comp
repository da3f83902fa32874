#version 450
// Multigrid restriction of a residual, R = Z^T (B - A X), for m columns (column-major):
// coarse row b G + k sums the residual rows b i + k of the fine blocks i of aggregate G
// (children[childOffsets[G] .. childOffsets[G + 1]]), each computed here from A's CSR row,
// read once per four columns (csr_rows.glsl). The fine residual is never stored: against
// a product, a subtraction and a restriction, one dispatch instead of three and no pass
// writing and reading it back. A gather per coarse row: no atomics, the same sums every
// run. Dispatch: one row of workgroups over the coarse rows.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer X { double x[]; };
layout(std430, binding = 4) readonly buffer B { double rhs[]; };
layout(std430, binding = 5) readonly buffer ChildOffsets { int childOffsets[]; };
layout(std430, binding = 6) readonly buffer Children { int children[]; };
layout(std430, binding = 7) writeonly buffer Coarse { double coarse[]; };

#include "csr_rows.glsl"

layout(push_constant) uniform Push {
  uint fineRows;
  uint coarseRows;
  uint m;
  uint b;
} pc;

void main() {
  GRID_STRIDE_LOOP(row, pc.coarseRows) {
    const uint aggregate = row / pc.b;
    const uint entry = row % pc.b;
    for (uint first = 0; first < pc.m; first += 4) {
      const uint width = min(4u, pc.m - first);
      dvec4 sum = dvec4(0.0);
      for (int c = childOffsets[aggregate]; c < childOffsets[aggregate + 1]; ++c) {
        const uint fineRow = uint(children[c]) * pc.b + entry;
        const dvec4 product = csrRowTimesColumns(fineRow, first, width, pc.fineRows);
        for (uint j = 0; j < width; ++j) {
          precise double residual = rhs[(first + j) * pc.fineRows + fineRow] - product[j];
          sum[j] += residual;
        }
      }
      for (uint j = 0; j < width; ++j) coarse[(first + j) * pc.coarseRows + row] = sum[j];
    }
  }
}
