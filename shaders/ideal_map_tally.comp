#version 450
// The tallies of the ideal-map kernel's methods (compute::IdealMapMethod), so that a loop
// that keeps the maps on the device reads three numbers instead of one method per face:
// tally[0] counts CornerProcrustes faces, tally[1] CentroidAtInfinity faces, and
// tally[2] = 0xffffffff - (the lowest CentroidAtInfinity face), 0 when there is none. The
// host zeroes the tally before the dispatch. Faces with either method are rare, so the
// atomics seldom meet.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Methods { int methods[]; };  // per face
layout(std430, binding = 1) buffer Tally { uint tally[]; };              // 3

layout(push_constant) uniform Push {
  uint faceCount;
} pc;

void main() {
  GRID_STRIDE_LOOP(f, pc.faceCount) {
    const int method = methods[f];
    if (method == 1) atomicAdd(tally[0], 1u);
    if (method == 2) {
      atomicAdd(tally[1], 1u);
      atomicMax(tally[2], 0xffffffffu - f);
    }
  }
}
