#version 450
// Multigrid prolongation F += Z C for m columns (column-major): fine row b i + k adds coarse
// row b aggregate[i] + k.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Aggregates { int aggregates[]; };
layout(std430, binding = 1) readonly buffer Coarse { double coarse[]; };
layout(std430, binding = 2) buffer Fine { double fine[]; };

layout(push_constant) uniform Push {
  uint fineRows;
  uint coarseRows;
  uint m;
  uint b;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.fineRows * pc.m) {
    const uint column = i / pc.fineRows;
    const uint row = i % pc.fineRows;
    const uint source = column * pc.coarseRows + uint(aggregates[row / pc.b]) * pc.b + row % pc.b;
    precise double value = fine[i] + coarse[source];
    fine[i] = value;
  }
}
