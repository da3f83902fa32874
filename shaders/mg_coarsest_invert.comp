#version 450
// In-place inversion of the multigrid's coarsest level (dense, row-major, symmetric
// positive definite) by the sweep operator, elimination steps [begin, end) per dispatch,
// in one workgroup: each step's updates need the whole previous step, and the level is
// small (at most a few hundred rows). A dispatch with begin = end = rows finishes it.
//
// Sweeping pivot k with d = a_kk: a_kk <- -1/d, a_ik <- a_ik / d (i != k) and a_ij <- a_ij
// - a_ik a_kj / d (i, j != k). Every step keeps the matrix symmetric, so only the upper
// triangle (j >= i) is updated: half the work of Gauss-Jordan, which keeps whole rows (a
// 256-row inversion 0.23 s on lavapipe, the whole cost of a rho update there). Sweeping
// every pivot leaves -A^-1; the finishing dispatch negates it and mirrors it into the lower
// triangle. Without pivoting, step k's pivot is the k-th pivot of K_c's LDL^T
// factorization, positive for every k exactly when K_c is positive definite: a pivot that
// is not positive (or not finite) stops the inversion and leaves `failureCode` in
// failure[0] (atomicMin: the host sets it to ~0 before).
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

// Column k of the step's matrix (= row k), before the step.
shared double factor[MG_COARSEST_MAX_ROWS];
shared double pivotInverse;
shared bool failed;

// The stored (upper) entry of the symmetric matrix at (i, j).
uint upper(uint i, uint j, uint n) { return i <= j ? i * n + j : j * n + i; }

void main() {
  const uint n = pc.rows;
  const uint lane = gl_LocalInvocationID.x;
  const uint lanes = gl_WorkGroupSize.x;
  if (pc.begin == n) {
    // Finish: A^-1 = -(the swept matrix), whole rows for the products that read it.
    if (failure[0] != 0xFFFFFFFFu) return;
    for (uint i = 0; i < n; ++i) {
      for (uint j = i + lane; j < n; j += lanes) {
        const double value = -a[i * n + j];
        a[i * n + j] = value;
        a[j * n + i] = value;
      }
    }
    return;
  }
  for (uint k = pc.begin; k < pc.end; ++k) {
    if (lane == 0) {
      const double pivot = a[k * n + k];
      failed = !(pivot > 0.0) || isinf(pivot) || failure[0] != 0xFFFFFFFFu;
      if (!(pivot > 0.0) || isinf(pivot)) atomicMin(failure[0], pc.failureCode);
      pivotInverse = 1.0 / pivot;
    }
    barrier();
    if (failed) return;  // uniform: read by every lane after the barrier
    for (uint i = lane; i < n; i += lanes) factor[i] = i == k ? 0.0 : a[upper(i, k, n)];
    memoryBarrierShared();
    barrier();
    // Row k and column k leave the update (their factor is 0 there) and take a_ik / d; the
    // pivot -1/d. Every entry is written by one lane and read by none in this step.
    for (uint i = 0; i < n; ++i) {
      if (i == k) continue;
      const double f = factor[i] * pivotInverse;
      for (uint j = i + lane; j < n; j += lanes) {
        if (j != k) a[i * n + j] -= f * factor[j];
      }
    }
    for (uint i = lane; i < n; i += lanes) a[upper(i, k, n)] = i == k ? -pivotInverse : factor[i] * pivotInverse;
    memoryBarrierBuffer();
    barrier();
  }
}
