#version 450
// Y = A X for a CSR matrix A (#rows x #cols) and m right-hand sides stored column after
// column (X: cols x m, Y: rows x m). Workgroup row y of the dispatch is the column.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer X { double x[]; };
layout(std430, binding = 4) writeonly buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint cols;
} pc;

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint xBase = column * pc.cols;
  GRID_STRIDE_LOOP(r, pc.rows) {
    double sum = 0.0;
    const int end = rowOffsets[r + 1];
    for (int e = rowOffsets[r]; e < end; ++e) sum += values[e] * x[xBase + uint(columns[e])];
    y[column * pc.rows + r] = sum;
  }
}
