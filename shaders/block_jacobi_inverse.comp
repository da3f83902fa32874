#version 450
// The block-Jacobi preconditioner of a CSR matrix A: the inverse of each b x b diagonal
// block (b <= 4; block j is rows and columns j b .. j b + b - 1), row-major, from its
// Cholesky factor L as L^-T L^-1. Computed where A lives so that an ADMM rho update moves
// no mesh-sized data. Only the lower triangle of a block is read (A is symmetric), as in
// the host's LLT. A block that is not positive definite or not finite leaves its index
// in failure[0] (atomicMin: the first such block; the host sets it to ~0 before).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) writeonly buffer Inverses { double inverses[]; };
layout(std430, binding = 4) buffer Failure { uint failure[]; };

layout(push_constant) uniform Push {
  uint blocks;  // n / b
  uint b;
} pc;

void main() {
  GRID_STRIDE_LOOP(block, pc.blocks) {
    const int b = int(pc.b);
    const int first = int(block) * b;
    double a[4][4];
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) a[i][j] = 0.0;
    }
    bool finite = true;
    for (int i = 0; i < b; ++i) {
      for (int e = rowOffsets[first + i]; e < rowOffsets[first + i + 1]; ++e) {
        const int j = columns[e] - first;
        if (j >= 0 && j <= i) {
          a[i][j] = values[e];
          finite = finite && !isnan(values[e]) && !isinf(values[e]);
        }
      }
    }
    // Cholesky A = L L^T, in place in the lower triangle.
    bool definite = finite;
    for (int j = 0; j < b && definite; ++j) {
      precise double d = a[j][j];
      for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
      definite = d > 0.0;
      if (!definite) break;
      a[j][j] = sqrt(d);
      for (int i = j + 1; i < b; ++i) {
        precise double s = a[i][j];
        for (int k = 0; k < j; ++k) s -= a[i][k] * a[j][k];
        a[i][j] = s / a[j][j];
      }
    }
    if (!definite) {
      atomicMin(failure[0], block);
      for (int t = 0; t < b * b; ++t) inverses[first * b + t] = 0.0;
      continue;
    }
    // W = L^-1 (lower triangular), then A^-1 = W^T W.
    double w[4][4];
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) w[i][j] = 0.0;
    }
    for (int i = 0; i < b; ++i) {
      w[i][i] = 1.0 / a[i][i];
      for (int j = 0; j < i; ++j) {
        precise double s = 0.0;
        for (int k = j; k < i; ++k) s += a[i][k] * w[k][j];
        w[i][j] = -s / a[i][i];
      }
    }
    for (int i = 0; i < b; ++i) {
      for (int j = 0; j < b; ++j) {
        precise double s = 0.0;
        for (int k = max(i, j); k < b; ++k) s += w[k][i] * w[k][j];
        inverses[first * b + i * b + j] = s;
      }
    }
  }
}
