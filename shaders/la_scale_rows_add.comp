#version 450
// Y += blockdiag(M) X for m columns of n entries, M's blocks stored as in la_scale_rows
// (block_rows.glsl): a smoothing step z += S t in one dispatch, without storing S t.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Blocks { double blocks[]; };
layout(std430, binding = 1) readonly buffer X { double x[]; };
layout(std430, binding = 2) buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint b;
} pc;

#include "block_rows.glsl"

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) {
    precise double value = blockRowTimes(i) + y[i];
    y[i] = value;
  }
}
