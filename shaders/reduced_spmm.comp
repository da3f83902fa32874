#version 450
// W = (S (x) I_k) N for a block of a basis's columns (compute/ReducedOperator.h): S a CSR
// #V x #V matrix, N and W k #V x columns, column after column, row k v + c coordinate c of
// vertex v. Workgroup row y of the dispatch is the column. Each entry sums over S's row in
// storage order, as the CPU reference's row-major sparse product does.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer Basis { double basis[]; };
layout(std430, binding = 4) writeonly buffer Product { double product[]; };

layout(push_constant) uniform Push {
  uint vertices;
  uint coordinates;  // k
} pc;

void main() {
  const uint rows = pc.vertices * pc.coordinates;
  const uint base = gl_WorkGroupID.y * rows;
  GRID_STRIDE_LOOP(r, rows) {
    const uint v = r / pc.coordinates;
    const uint c = r - v * pc.coordinates;
    precise double sum = 0.0;
    const int end = rowOffsets[v + 1];
    for (int e = rowOffsets[v]; e < end; ++e) sum += values[e] * basis[base + uint(columns[e]) * pc.coordinates + c];
    product[base + r] = sum;
  }
}
