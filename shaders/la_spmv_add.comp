#version 450
// Y += A X for a CSR matrix A (#rows x #cols) and m columns stored column after column
// (X: cols x m, Y: rows x m): the smoothed multigrid's prolongation z += P z_coarse. Each
// invocation takes a row for every column, reading A's row once per four columns
// (csr_rows.glsl); dispatch: one row of workgroups.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer X { double x[]; };
layout(std430, binding = 4) buffer Y { double y[]; };

#include "csr_rows.glsl"

layout(push_constant) uniform Push {
  uint rows;
  uint cols;
  uint m;
} pc;

void main() {
  GRID_STRIDE_LOOP(r, pc.rows) {
    for (uint first = 0; first < pc.m; first += 4) {
      const uint width = min(4u, pc.m - first);
      const dvec4 product = csrRowTimesColumns(r, first, width, pc.cols);
      for (uint j = 0; j < width; ++j) {
        const uint at = (first + j) * pc.rows + r;
        precise double sum = y[at] + product[j];
        y[at] = sum;
      }
    }
  }
}
