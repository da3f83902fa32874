#version 450
// In-place inversion of the multigrid's coarsest level (dense, row-major, symmetric
// positive definite) by the sweep operator, one elimination step per dispatch over several
// workgroups; a last dispatch (step = rows) finishes it.
//
// Sweeping pivot k with d = a_kk: a_kk <- -1/d, a_ik <- a_ik / d (i != k) and a_ij <- a_ij
// - a_ik a_kj / d (i, j != k). Every step keeps the matrix symmetric, so only the upper
// triangle (j >= i) is updated: half the work of Gauss-Jordan, which keeps whole rows.
// Sweeping every pivot leaves -A^-1; the finishing dispatch negates it and mirrors it into
// the lower triangle, whole rows for the products that read it.
//
// Workgroup w takes the rows i = w (mod workgroups), its lanes the entries j = i + lane (mod
// lanes) of each: every entry (i, j) of the upper triangle belongs to one invocation in
// every step, which reads and writes only it, so the workgroups of a step need no
// synchronization with one another. The one conflict, step
// k's readers of column k against its writers, is avoided by deferring column k's new
// values to step k + 1: step k leaves row and column k as they were and saves their old
// values and d (`saved`, two slots, one written and one read per step); step k + 1's
// owners write a_kk = -1/d and a_ik = a_ik(old) / d first, then update those entries as
// any other, and its readers of column k + 1 take a_(k, k+1) from the saved slot. One
// workgroup running every step in sequence (before, 0.13 s per 256 rows on lavapipe) left
// all other cores idle; a GPU's hundreds of multiprocessors, all but one.
//
// Without pivoting, step k's pivot is the k-th pivot of K_c's LDL^T factorization,
// positive for every k exactly when K_c is positive definite: a pivot that is not positive
// (or not finite) stops the inversion and leaves `failureCode` in failure[0] (atomicMin:
// the host sets it to ~0 before; later steps see it and return).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x_id = 0) in;

// vk::Multigrid::kMaxCoarsestRows.
#define MG_COARSEST_MAX_ROWS 1024

layout(std430, binding = 0) buffer Dense { double a[]; };
layout(std430, binding = 1) coherent buffer Failure { uint failure[]; };
// Two slots of rows + 1: a step's old column of its pivot, then the pivot.
layout(std430, binding = 2) buffer Saved { double saved[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint step;  // the pivot swept; rows: finish
  uint failureCode;
  uint unused;
} pc;

// Column k of the step's matrix (0 at row k), as it was before the step.
shared double column[MG_COARSEST_MAX_ROWS];
shared double pivot;
shared double previousInverse;
shared bool failed;

// The stored (upper) entry of the symmetric matrix at (i, j).
uint upper(uint i, uint j, uint n) { return i <= j ? i * n + j : j * n + i; }

void main() {
  const uint n = pc.rows;
  const uint k = pc.step;
  const uint lane = gl_LocalInvocationID.x;
  const uint lanes = gl_WorkGroupSize.x;
  const uint group = gl_WorkGroupID.x;
  const uint groups = gl_NumWorkGroups.x;
  const bool finish = k == n;
  const bool deferred = k > 0;  // step k - 1's row and column are written here
  const uint previous = k - 1;
  const uint previousSlot = (previous % 2) * (n + 1), slot = (k % 2) * (n + 1);
  if (lane == 0) {
    failed = failure[0] != 0xFFFFFFFFu;
    if (!failed && !finish) {
      pivot = a[k * n + k];
      if (!(pivot > 0.0) || isinf(pivot)) {
        failed = true;
        atomicMin(failure[0], pc.failureCode);
      }
    }
    previousInverse = deferred ? 1.0 / saved[previousSlot + n] : 0.0;
  }
  barrier();
  if (failed) return;  // uniform: read by every lane after the barrier
  if (!finish) {
    for (uint i = lane; i < n; i += lanes) {
      double value = 0.0;
      if (i == previous && deferred) {
        value = saved[previousSlot + k] * previousInverse;
      } else if (i != k) {
        value = a[upper(i, k, n)];
      }
      column[i] = value;
    }
    memoryBarrierShared();
    barrier();
    if (group == 0) {
      for (uint i = lane; i < n; i += lanes) saved[slot + i] = column[i];
      if (lane == 0) saved[slot + n] = pivot;
    }
  }
  const double pivotInverse = finish ? 0.0 : 1.0 / pivot;
  for (uint i = group; i < n; i += groups) {
    const double factor = finish ? 0.0 : column[i] * pivotInverse;
    for (uint j = i + lane; j < n; j += lanes) {
      const bool inPrevious = deferred && (i == previous || j == previous);
      const bool inPivot = !finish && (i == k || j == k);
      // Row and column k are read by this step (column, pivot) and left for the next.
      if (inPivot && !inPrevious) continue;
      double value = a[i * n + j];
      if (inPrevious) {
        const uint other = i == previous ? j : i;
        value = other == previous ? -previousInverse : saved[previousSlot + other] * previousInverse;
      }
      if (finish) {
        value = -value;
        a[j * n + i] = value;
      } else if (!inPivot) {
        value -= factor * column[j];
      }
      a[i * n + j] = value;
    }
  }
}
