#version 450
// One block of R = N^T W (compute/ReducedOperator.h): R[i0 + i, j0 + j] = sum_r A[r, i]
// B[r, j] for A a block of the basis's columns and B = (S (x) I_k) N of another block, both
// n x (their columns) column after column, R d x d column-major.
//
// Each workgroup of 16 x 16 invocations computes a 64 x 64 block of R over one chunk of the
// long dimension r, each invocation a 4 x 4 set of its entries (i = tx + 16 a, j = ty + 16 b)
// held in registers, reading the chunk in 16-row slices through shared memory: a slice of A
// and of B is read from the buffers once per workgroup, and each value read from shared
// memory feeds four multiply-adds. The chunks (split-K) give a tall basis, whose R has few
// 64 x 64 blocks, enough workgroups to fill a device: each writes its partial sums to its
// own copy of R, which shaders/reduced_sum_partials.comp adds up in chunk order.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

#define THREADS 16
#define PER_THREAD 4
#define TILE (THREADS * PER_THREAD)  // 64: vk::ReducedOperatorKernel's kTile
#define SLICE 16

layout(local_size_x = THREADS, local_size_y = THREADS) in;

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
  uint tilesB;       // 64-column tiles of B: workgroup row y is chunk * tilesB + tile
  uint rowsPerChunk; // a multiple of 16
} pc;

shared double sliceA[TILE][SLICE];  // [column of A within the tile][row within the slice]
shared double sliceB[TILE][SLICE];

void main() {
  const uint tx = gl_LocalInvocationID.x;
  const uint ty = gl_LocalInvocationID.y;
  const uint thread = tx + THREADS * ty;
  const uint tileA = gl_WorkGroupID.x * TILE;  // first column of A (row of R) of this block
  const uint chunk = gl_WorkGroupID.y / pc.tilesB;
  const uint tileB = (gl_WorkGroupID.y - chunk * pc.tilesB) * TILE;
  const uint firstR = chunk * pc.rowsPerChunk;
  const uint endR = min(pc.n, firstR + pc.rowsPerChunk);
  double sum[PER_THREAD][PER_THREAD];
  for (uint p = 0; p < PER_THREAD; ++p)
    for (uint q = 0; q < PER_THREAD; ++q) sum[p][q] = 0.0;
  for (uint r0 = firstR; r0 < endR; r0 += SLICE) {
    // 64 x 16 values of each slice, four per invocation; consecutive invocations read
    // consecutive rows of a column.
    for (uint e = thread; e < TILE * SLICE; e += THREADS * THREADS) {
      const uint row = e % SLICE;
      const uint column = e / SLICE;
      const uint r = r0 + row;
      sliceA[column][row] = (r < endR && tileA + column < pc.columnsA) ? a[(tileA + column) * pc.n + r] : 0.0;
      sliceB[column][row] = (r < endR && tileB + column < pc.columnsB) ? b[(tileB + column) * pc.n + r] : 0.0;
    }
    barrier();
    for (uint k = 0; k < SLICE; ++k) {
      double x[PER_THREAD], y[PER_THREAD];
      for (uint p = 0; p < PER_THREAD; ++p) {
        x[p] = sliceA[tx + THREADS * p][k];
        y[p] = sliceB[ty + THREADS * p][k];
      }
      for (uint p = 0; p < PER_THREAD; ++p)
        for (uint q = 0; q < PER_THREAD; ++q) {
          precise double t = sum[p][q] + x[p] * y[q];
          sum[p][q] = t;
        }
    }
    barrier();
  }
  for (uint p = 0; p < PER_THREAD; ++p)
    for (uint q = 0; q < PER_THREAD; ++q) {
      const uint i = tileA + tx + THREADS * p;
      const uint j = tileB + ty + THREADS * q;
      if (i < pc.columnsA && j < pc.columnsB) {
        result[chunk * pc.d * pc.d + (pc.firstColumn + j) * pc.d + pc.firstRow + i] = sum[p][q];
      }
    }
}
