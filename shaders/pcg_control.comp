#version 450
// Device-side convergence control of a PCG solve recorded as a fixed number of iterations
// (the inner solve of the device ADMM). Run before each recorded iteration, it writes the
// indirect dispatch sizes of that iteration: its full sizes while some column still has
// r.z > tol^2 b.z or r.r > abs^2, zero once all have converged, so the rest of the
// recorded iterations cost empty dispatches and the solution is that of a PCG stopped at
// the tolerance, or (where slotFloor names b.z's slot) once r.z <= floor^2 b.z, the
// rounding floor of a solve whose own target is relative to its warm start's residual.
// NaN counts as not converged, so that it reaches the iterate. state: [0]
// done flag of this solve, [1] iterations run, [2] solves stopped by the recorded cap,
// [3] abs^2, an absolute bound the host derives from the ADMM's residuals (compute/Admm.h),
// [STATE_SOLVE_START] [1] when this solve began, [STATE_LARGEST] the most iterations a
// counted solve ran since the ADMM's start (the host sizes the next blocks' recordings by it),
// [STATE_BLOCK_CAPPED] [2] when the current ADMM block began. A block recorded with a cap the
// host would raise and run again after a capped solve (vk::AdmmKernels::measure) skips the
// solves after one: their iterates are discarded, so only their PCG iterations would be lost.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 1) in;

// vk::AdmmKernels' State slots kSolveStart and kLargestSolve.
#define STATE_SOLVE_START 20
#define STATE_LARGEST 21
#define STATE_BLOCK_CAPPED 22

layout(std430, binding = 0) readonly buffer Scalars { double scalars[]; };
layout(std430, binding = 1) buffer State { double state[]; };
layout(std430, binding = 2) writeonly buffer Arguments { uint arguments[]; };

layout(push_constant) uniform Push {
  uint m;
  uint slotRz;  // r.z of the current iterate; its r.r is in the next slot
  uint slotBz;
  uint mode;  // 0: first check of a solve, 1: later check, 2: after the last recorded iteration
  uint groupsColumn;     // workgroups per column of the fused PCG kernels
  uint groupsDirection;  // workgroups of the direction update
  uint slotFloor;  // b.z of the right-hand side for the rounding floor; ~0u: none
  uint countLargest;  // 1: this solve counts into STATE_LARGEST
  double tolerance2;
  double floor2;
  uint blockStart;       // 1: the first solve of an ADMM block (sets STATE_BLOCK_CAPPED)
  uint abandonAfterCap;  // 1: skip this solve when one since the block's start was capped
} pc;

void main() {
  if (pc.mode == 0) {
    state[0] = 0.0;
    state[STATE_SOLVE_START] = state[1];
    if (pc.blockStart != 0u) state[STATE_BLOCK_CAPPED] = state[2];
    if (pc.abandonAfterCap != 0u && state[2] > state[STATE_BLOCK_CAPPED]) state[0] = 1.0;
  }
  bool running = state[0] == 0.0;
  if (running) {
    bool any = false;
    for (uint c = 0; c < pc.m; ++c) {
      const double rz = scalars[pc.slotRz * pc.m + c], rr = scalars[(pc.slotRz + 1) * pc.m + c];
      const bool reached = rz <= pc.tolerance2 * scalars[pc.slotBz * pc.m + c] ||
                           (pc.slotFloor != ~0u && rz <= pc.floor2 * scalars[pc.slotFloor * pc.m + c]);
      if (!reached || !(rr <= state[3])) any = true;
    }
    running = any;
  }
  if (pc.mode == 2) {
    if (running) state[2] += 1.0;
    return;
  }
  if (running) {
    state[1] += 1.0;
    if (pc.countLargest != 0u) {
      state[STATE_LARGEST] = max(state[STATE_LARGEST], state[1] - state[STATE_SOLVE_START]);
    }
  } else {
    state[0] = 1.0;
  }
  // [0..2]: fused kernels (groupsColumn x m), [3..5]: reductions (m), [6..8]: direction,
  // [9..11]: paired reductions (2m: r.z and r.r), [12..14]: the product, whose workgroups
  // take every column (groupsColumn x 1).
  arguments[0] = running ? pc.groupsColumn : 0;
  arguments[1] = pc.m;
  arguments[2] = 1;
  arguments[3] = running ? pc.m : 0;
  arguments[4] = 1;
  arguments[5] = 1;
  arguments[6] = running ? pc.groupsDirection : 0;
  arguments[7] = 1;
  arguments[8] = 1;
  arguments[9] = running ? 2 * pc.m : 0;
  arguments[10] = 1;
  arguments[11] = 1;
  arguments[12] = running ? pc.groupsColumn : 0;
  arguments[13] = 1;
  arguments[14] = 1;
}
