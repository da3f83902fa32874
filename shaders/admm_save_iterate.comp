#version 450
// Saves the iterate an ADMM iteration of a multi-dispatch block starts from (x, xTilde, y,
// z), so that vk::AdmmKernels::measure can run the block again from the iteration whose
// solve stopped at a cap, not from the block's start: the iterations before it were exact
// and are kept. The block's first iteration always saves; a later one only while no solve
// since the block's start was capped (pcg_control's STATE_BLOCK_CAPPED), so that the copy
// holds the start of the first capped iteration. The thread that saves the first element
// notes which iteration it was (STATE_SAVED_ITERATION).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

// vk::AdmmKernels' State slots kCappedSolves, kBlockCapped and kSavedIteration.
#define STATE_CAPPED 2
#define STATE_BLOCK_CAPPED 22
#define STATE_SAVED_ITERATION 23

layout(std430, binding = 0) buffer State { double state[]; };
layout(std430, binding = 1) readonly buffer X { double x[]; };
layout(std430, binding = 2) readonly buffer XTilde { double xTilde[]; };
layout(std430, binding = 3) readonly buffer Y { double y[]; };
layout(std430, binding = 4) readonly buffer Z { double z[]; };
layout(std430, binding = 5) writeonly buffer XSaved { double xSaved[]; };
layout(std430, binding = 6) writeonly buffer XTildeSaved { double xTildeSaved[]; };
layout(std430, binding = 7) writeonly buffer YSaved { double ySaved[]; };
layout(std430, binding = 8) writeonly buffer ZSaved { double zSaved[]; };

layout(push_constant) uniform Push {
  uint nk;         // entries of x and xTilde
  uint mk;         // entries of y and z
  uint iteration;  // the iteration's index in its block
  uint always;     // 1: the block's first iteration (saves whatever the state says)
} pc;

void main() {
  if (pc.always == 0u && state[STATE_CAPPED] > state[STATE_BLOCK_CAPPED]) return;
  if (gl_GlobalInvocationID.x == 0u) state[STATE_SAVED_ITERATION] = double(pc.iteration);
  GRID_STRIDE_LOOP(i, pc.nk) {
    xSaved[i] = x[i];
    xTildeSaved[i] = xTilde[i];
  }
  GRID_STRIDE_LOOP(i, pc.mk) {
    ySaved[i] = y[i];
    zSaved[i] = z[i];
  }
}
