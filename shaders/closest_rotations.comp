#version 450
// Batched orthogonal Procrustes (projective-maps paper, App. A): for each 3x3 matrix
// M = U S V^T, the closest rotation R = U diag(1, 1, d) V^T with d = det(U V^T), and the
// signed singular values (s1, s2, d s3), s1 >= s2 >= s3 >= 0.
//
// One invocation per matrix; the SVD is a one-sided Jacobi iteration on the columns of M
// (M V = U S), accurate to working precision, including for (near-)singular M.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Matrices { double matrices[]; };    // 9 per matrix, column-major
layout(std430, binding = 1) writeonly buffer Rotations { double rotations[]; };  // 9 per matrix, column-major
layout(std430, binding = 2) writeonly buffer Singular { double singular[]; };    // 3 per matrix

layout(push_constant) uniform Push {
  uint count;  // matrices in this dispatch (the host splits large batches)
} pc;

void swapColumns(inout dmat3 A, inout dmat3 V, inout double s[3], int a, int b) {
  const dvec3 ta = A[a];
  A[a] = A[b];
  A[b] = ta;
  const dvec3 tv = V[a];
  V[a] = V[b];
  V[b] = tv;
  const double t = s[a];
  s[a] = s[b];
  s[b] = t;
}

void main() {
  GRID_STRIDE_LOOP(i, pc.count) {
    dmat3 A;
    for (int col = 0; col < 3; ++col) {
      for (int r = 0; r < 3; ++r) A[col][r] = matrices[9 * i + 3 * col + r];
    }
    dmat3 V = dmat3(1.0);
    for (int sweep = 0; sweep < 30; ++sweep) {
      bool rotated = false;
      for (int p = 0; p < 2; ++p) {
        for (int q = p + 1; q < 3; ++q) {
          const double alpha = dot3(A[p], A[p]);
          const double beta = dot3(A[q], A[q]);
          const double gamma = dot3(A[p], A[q]);
          if (!(abs(gamma) > 1e-15 * sqrt(alpha * beta))) continue;
          rotated = true;
          const double zeta = (beta - alpha) / (2.0 * gamma);
          const double t = (zeta >= 0.0 ? 1.0 : -1.0) / (abs(zeta) + sqrt(1.0 + zeta * zeta));
          const double cs = 1.0 / sqrt(1.0 + t * t);
          const double sn = cs * t;
          const dvec3 ap = A[p];
          A[p] = cs * ap - sn * A[q];
          A[q] = sn * ap + cs * A[q];
          const dvec3 vp = V[p];
          V[p] = cs * vp - sn * V[q];
          V[q] = sn * vp + cs * V[q];
        }
      }
      if (!rotated) break;
    }
    double s[3] = double[3](norm3(A[0]), norm3(A[1]), norm3(A[2]));
    // Sort descending (three compare-exchanges), permuting the columns alike.
    if (s[0] < s[1]) swapColumns(A, V, s, 0, 1);
    if (s[1] < s[2]) swapColumns(A, V, s, 1, 2);
    if (s[0] < s[1]) swapColumns(A, V, s, 0, 1);

    dmat3 U;
    U[0] = s[0] > 0.0 ? A[0] / s[0] : dvec3(1.0, 0.0, 0.0);
    if (s[1] > 0.0) {
      U[1] = A[1] / s[1];
    } else {
      // Rank <= 1: any unit vector orthogonal to U[0] (R is not unique then).
      const dvec3 axis = abs(U[0].x) < 0.9 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 1.0, 0.0);
      U[1] = normalize(cross3(U[0], axis));
    }
    // The third left vector completes an orthonormal basis; its sign follows A[2] so that
    // U S V^T = M, and d absorbs the orientation.
    const dvec3 w = cross3(U[0], U[1]);
    U[2] = dot3(A[2], w) < 0.0 ? -w : w;
    const double d = determinant(U * transpose(V)) < 0.0 ? -1.0 : 1.0;
    const dmat3 R = U * dmat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, d) * transpose(V);
    for (int col = 0; col < 3; ++col) {
      for (int r = 0; r < 3; ++r) rotations[9 * i + 3 * col + r] = R[col][r];
    }
    singular[3 * i] = s[0];
    singular[3 * i + 1] = s[1];
    singular[3 * i + 2] = d * s[2];
  }
}
