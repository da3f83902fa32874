#version 450
// Bounds of the epsilon-relaxed constraints (compute::RelaxedBounds):
// L = centre - epsilon, U = centre + epsilon on the rows flagged relaxed, L = U = centre on
// the others, for the m x k column-major centre. epsilon comes from the ADMM's state
// buffer (uploaded with it at each start), so one recording serves every attempt of an
// epsilon schedule.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Centre { double centre[]; };
layout(std430, binding = 1) readonly buffer Relaxed { uint relaxed[]; };
layout(std430, binding = 2) readonly buffer State { double state[]; };
layout(std430, binding = 3) writeonly buffer L { double lower[]; };
layout(std430, binding = 4) writeonly buffer U { double upper[]; };

layout(push_constant) uniform Push {
  uint rows;
  uint count;
  uint epsilonSlot;
} pc;

void main() {
  const double epsilon = state[pc.epsilonSlot];
  GRID_STRIDE_LOOP(i, pc.count) {
    const double offset = relaxed[i % pc.rows] != 0u ? epsilon : 0.0;
    lower[i] = centre[i] - offset;
    upper[i] = centre[i] + offset;
  }
}
