#version 450
// Batched orthogonal Procrustes (projective-maps paper, App. A): for each 3x3 matrix
// M = U S V^T, the closest rotation R = U diag(1, 1, d) V^T with d = det(U V^T), and the
// signed singular values (s1, s2, d s3), s1 >= s2 >= s3 >= 0 (procrustes.glsl).
//
// One invocation per matrix.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "procrustes.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Matrices { double matrices[]; };    // 9 per matrix, column-major
layout(std430, binding = 1) writeonly buffer Rotations { double rotations[]; };  // 9 per matrix, column-major
layout(std430, binding = 2) writeonly buffer Singular { double singular[]; };    // 3 per matrix

layout(push_constant) uniform Push {
  uint count;  // matrices in this dispatch (the host splits large batches)
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.count) {
    dmat3 A;
    for (int col = 0; col < 3; ++col) {
      for (int r = 0; r < 3; ++r) A[col][r] = matrices[9 * i + 3 * col + r];
    }
    dmat3 R;
    dvec3 s;
    closestRotation(A, R, s);
    for (int col = 0; col < 3; ++col) {
      for (int r = 0; r < 3; ++r) rotations[9 * i + 3 * col + r] = R[col][r];
    }
    singular[3 * i] = s.x;
    singular[3 * i + 1] = s.y;
    singular[3 * i + 2] = s.z;
  }
}
