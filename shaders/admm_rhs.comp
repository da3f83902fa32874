#version 450
// The two elementwise parts of the ADMM right-hand side sigma x - q + C^T (rho z - y)
// (k columns, column-major):
//   mode 0, over the m x k constraint rows:  W = rho z - y   (rho per row)
//   mode 1, over the n x k unknowns:         B = sigma X - Q + T   with T = C^T W
// The operation order is the host's (Eigen, no fused multiply-adds).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer U { double u[]; };   // z | x
layout(std430, binding = 1) readonly buffer V { double v[]; };   // y | q
layout(std430, binding = 2) readonly buffer S { double s[]; };   // rho (m) | T
layout(std430, binding = 3) writeonly buffer Out { double result[]; };  // W | B

layout(push_constant) uniform Push {
  uint rows;  // m (mode 0) or n (mode 1)
  uint count; // rows * k
  uint mode;
  uint pad;
  double sigma;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) {
    if (pc.mode == 0) {
      precise double w = s[i % pc.rows] * u[i] - v[i];
      result[i] = w;
    } else {
      precise double b = (pc.sigma * u[i] - v[i]) + s[i];
      result[i] = b;
    }
  }
}
