#version 450
// One block of R = N^T W (compute/ReducedOperator.h): R[i0 + i, j0 + j] = sum_r A[r, i]
// B[r, j] for A a block of the basis's columns and B = (S (x) I_k) N of another block, both
// n x (their columns) column after column, R d x d column-major. Each workgroup computes a
// TILE x TILE block of R, reading the long dimension r in TILE-row slices through shared
// memory: each slice of A and B is read from the buffers once per workgroup instead of once
// per output entry, and consecutive invocations read consecutive rows.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

#define TILE 16
layout(local_size_x = TILE, local_size_y = TILE) in;

layout(std430, binding = 0) readonly buffer A { double a[]; };
layout(std430, binding = 1) readonly buffer B { double b[]; };
layout(std430, binding = 2) buffer R { double result[]; };

layout(push_constant) uniform Push {
  uint n;            // rows of A and B
  uint columnsA;     // columns of A: rows i of this block of R
  uint columnsB;     // columns of B: columns j of this block of R
  uint firstRow;     // i0
  uint firstColumn;  // j0
  uint d;            // leading dimension of R
} pc;

shared double sliceA[TILE][TILE];  // [column of A][row of the slice]
shared double sliceB[TILE][TILE];

void main() {
  const uint tx = gl_LocalInvocationID.x;
  const uint ty = gl_LocalInvocationID.y;
  const uint i = gl_WorkGroupID.x * TILE + tx;  // this invocation's entry (i, j)
  const uint j = gl_WorkGroupID.y * TILE + ty;
  // This invocation loads row r0 + tx of column (tile's first) + ty of A and of B.
  const uint loadA = gl_WorkGroupID.x * TILE + ty;
  const uint loadB = gl_WorkGroupID.y * TILE + ty;
  precise double sum = 0.0;
  for (uint r0 = 0; r0 < pc.n; r0 += TILE) {
    const uint r = r0 + tx;
    sliceA[ty][tx] = (r < pc.n && loadA < pc.columnsA) ? a[loadA * pc.n + r] : 0.0;
    sliceB[ty][tx] = (r < pc.n && loadB < pc.columnsB) ? b[loadB * pc.n + r] : 0.0;
    barrier();
    for (uint k = 0; k < TILE; ++k) sum += sliceA[tx][k] * sliceB[ty][k];
    barrier();
  }
  if (i < pc.columnsA && j < pc.columnsB) result[(pc.firstColumn + j) * pc.d + pc.firstRow + i] = sum;
}
