// Orthogonal Procrustes of one 3x3 matrix (projective-maps paper, App. A), shared by
// closest_rotations.comp and ideal_maps.comp (include after common.glsl): M = U S V^T,
// the closest rotation R = U diag(1, 1, d) V^T with d = det(U V^T), and the signed
// singular values (s1, s2, d s3), s1 >= s2 >= s3 >= 0.
//
// The SVD is a one-sided Jacobi iteration on the columns of M (M V = U S), accurate to
// working precision, including for (near-)singular M.

void procrustesSwapColumns(inout dmat3 A, inout dmat3 V, inout double s[3], int a, int b) {
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

void closestRotation(dmat3 A, out dmat3 R, out dvec3 singular) {
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
  if (s[0] < s[1]) procrustesSwapColumns(A, V, s, 0, 1);
  if (s[1] < s[2]) procrustesSwapColumns(A, V, s, 1, 2);
  if (s[0] < s[1]) procrustesSwapColumns(A, V, s, 0, 1);

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
  R = U * dmat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, d) * transpose(V);
  singular = dvec3(s[0], s[1], d * s[2]);
}
