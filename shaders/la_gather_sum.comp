#version 450
// out[i] = the sum of in[index[t]] over t = offsets[i] .. offsets[i + 1] - 1, in that
// order: a fixed sparse linear map between value arrays, e.g. a coarse matrix's values
// from a fine one's (each fine entry feeds one coarse entry) or a transpose's values from
// its matrix's (one term each).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Offsets { int offsets[]; };
layout(std430, binding = 1) readonly buffer Indices { int indices[]; };
layout(std430, binding = 2) readonly buffer Source { double source[]; };
layout(std430, binding = 3) writeonly buffer Destination { double destination[]; };

layout(push_constant) uniform Push {
  uint count;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) {
    precise double sum = 0.0;
    for (int t = offsets[i]; t < offsets[i + 1]; ++t) sum += source[indices[t]];
    destination[i] = sum;
  }
}
