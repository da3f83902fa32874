#version 450
// Multigrid restriction R = Z^T F for m columns (column-major): coarse row b B + k is the
// sum of fine rows b i + k over the fine blocks i of aggregate B (children[childOffsets[B]
// .. childOffsets[B + 1]]). A gather per coarse row: no atomics, the same sums every run.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer ChildOffsets { int childOffsets[]; };
layout(std430, binding = 1) readonly buffer Children { int children[]; };
layout(std430, binding = 2) readonly buffer Fine { double fine[]; };
layout(std430, binding = 3) writeonly buffer Coarse { double coarse[]; };

layout(push_constant) uniform Push {
  uint fineRows;
  uint coarseRows;
  uint m;
  uint b;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.coarseRows * pc.m) {
    const uint column = i / pc.coarseRows;
    const uint row = i % pc.coarseRows;
    const uint aggregate = row / pc.b;
    const uint entry = row % pc.b;
    double sum = 0.0;
    for (int e = childOffsets[aggregate]; e < childOffsets[aggregate + 1]; ++e) {
      sum += fine[column * pc.fineRows + uint(children[e]) * pc.b + entry];
    }
    coarse[i] = sum;
  }
}
