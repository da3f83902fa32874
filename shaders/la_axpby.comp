#version 450
// Y = a X + b Y over `count` entries (a, b from the host).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer X { double x[]; };
layout(std430, binding = 1) buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint count;
  uint pad;
  double a;
  double b;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) { y[i] = pc.a * x[i] + pc.b * y[i]; }
}
