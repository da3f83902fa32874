#version 450
// In-place Gauss-Jordan inversion of the multigrid's coarsest level (dense, row-major,
// symmetric positive definite), elimination steps [begin, end) per dispatch, in one
// workgroup: each step's row and column updates need the whole previous step, and the
// level is small (at most a few hundred rows). Without pivoting, step k's pivot is the
// k-th pivot of K_c's LDL^T factorization, positive for every k exactly when K_c is
// positive definite: a pivot that is not positive (or not finite) stops the inversion
// and leaves `failureCode` in failure[0] (atomicMin: the host sets it to ~0 before).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x_id = 0) in;

// vk::Multigrid::kMaxCoarsestRows.
#define MG_COARSEST_MAX_ROWS 1024

// coherent: every step reads what other lanes of the workgroup wrote in the step before.
layout(std430, binding = 0) coherent buffer Dense { double a[]; };
layout(std430, binding = 1) coherent buffer Failure { uint failure[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint begin;
  uint end;
  uint failureCode;
} pc;

// Column k of the step's matrix, before the step (its entries leave the matrix first).
shared double factor[MG_COARSEST_MAX_ROWS];
shared double pivotInverse;
shared bool failed;

void main() {
  const uint n = pc.rows;
  const uint lane = gl_LocalInvocationID.x;
  const uint lanes = gl_WorkGroupSize.x;
  for (uint k = pc.begin; k < pc.end; ++k) {
    if (lane == 0) {
      const double pivot = a[k * n + k];
      failed = !(pivot > 0.0) || isinf(pivot) || failure[0] != 0xFFFFFFFFu;
      if (!(pivot > 0.0) || isinf(pivot)) atomicMin(failure[0], pc.failureCode);
      pivotInverse = 1.0 / pivot;
    }
    barrier();
    if (failed) return;  // uniform: read by every lane after the barrier
    for (uint i = lane; i < n; i += lanes) factor[i] = i == k ? 0.0 : a[i * n + k];
    // Row k: (row k with a_kk replaced by 1) / pivot.
    for (uint j = lane; j < n; j += lanes) a[k * n + j] = (j == k ? 1.0 : a[k * n + j]) * pivotInverse;
    memoryBarrierBuffer();
    memoryBarrierShared();
    barrier();
    // Every other row: (row with a_ik replaced by 0) - a_ik * new row k.
    for (uint e = lane; e < n * n; e += lanes) {
      const uint i = e / n;
      if (i == k) continue;
      const uint j = e - i * n;
      a[e] = (j == k ? 0.0 : a[e]) - factor[i] * a[k * n + j];
    }
    memoryBarrierBuffer();
    barrier();
  }
}
