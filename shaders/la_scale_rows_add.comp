#version 450
// Y += blockdiag(M) X for m columns of n entries, M's n / b dense b x b blocks stored as in
// la_scale_rows (row-major, block j acting on rows j b .. j b + b - 1): a smoothing step
// z += S t in one dispatch, without storing S t.
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

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) {
    const uint row = i % pc.n;
    const uint first = row - row % pc.b;  // first row of the block, in this column
    const uint base = i - (row - first);
    const uint entries = (row / pc.b) * pc.b * pc.b + (row - first) * pc.b;
    double sum = 0.0;
    for (uint t = 0; t < pc.b; ++t) sum += blocks[entries + t] * x[base + t];
    precise double value = sum + y[i];
    y[i] = value;
  }
}
