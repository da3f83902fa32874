#version 450
// The polish's targets from the active sides (admm_active_sides' packing): b = l where an
// entry is held at its lower bound, u at its upper, 0 where it is free.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Sides { uint sides[]; };
layout(std430, binding = 1) readonly buffer L { double lower[]; };
layout(std430, binding = 2) readonly buffer U { double upper[]; };
layout(std430, binding = 3) writeonly buffer B { double targets[]; };

layout(push_constant) uniform Push {
  uint count;  // m k entries
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.count) {
    const uint side = (sides[e / 16u] >> (2u * (e % 16u))) & 3u;
    targets[e] = side == 1u ? lower[e] : (side == 2u ? upper[e] : 0.0);
  }
}
