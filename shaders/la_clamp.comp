#version 450
// Box projection Y = min(max(X, L), U), entry by entry (the epsilon-relaxed constraints
// of the global step).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer X { double x[]; };
layout(std430, binding = 1) readonly buffer L { double lower[]; };
layout(std430, binding = 2) readonly buffer U { double upper[]; };
layout(std430, binding = 3) writeonly buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint count;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) { y[i] = min(max(x[i], lower[i]), upper[i]); }
}
