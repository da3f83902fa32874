#version 450
// Batched local step of the projective-maps paper (§4.1, Eq. 3), the math of
// src/projective/LocalFit.cpp: per face, project source and target corners onto their
// best-fit planes, centre both at their own centroids (p' = p - c_p, q' = q - c_q), then
// find the 15 free entries t of the 4x4 map T' (T'(3,3) = 1) from the 3k equations
// (p'_i, 1) T'[:, j] - q'_ij (p'_i, 1) T'[:, 3] = 0, as the correction from the identity of
// least norm (least squares when inconsistent). Centring excludes the degenerate exact fit
// that collapses the face onto (p, 1) T = 0 (all reciprocal scales 0); the map is then
// converted back, T = S_p T' S_q^{-1}, and rescaled to T(3,3) = 1 (see LocalFit.h).
//
// One invocation per face. The 3k x 15 system is never stored: its rows are streamed
// into a 15 x 15 triangular factor R by Givens rotations (M = Q [R; 0], so the minimum-norm
// least-squares solutions of M x = r and R x = Q^T r coincide). R then gets the complete
// orthogonal decomposition the CPU reference applies to M: Householder QR with column
// pivoting, numerical rank = number of pivots |R_ii| > rankThreshold * |R_00| (column
// norms, hence pivots, are the same for M and R), and Householder reflections from the
// right that turn [R11 R12] into [T 0], giving the minimum-norm solution. No normal
// equations: planar faces give rank-deficient systems by design, and squaring their
// condition number would blur the rank decision.
//
// The per-face work arrays are private to the invocation. (Measured on lavapipe: slices
// of shared memory instead, [element][lane], ran about 3x slower, and a one-sided Jacobi SVD
// instead of the QR-based decomposition ~10x slower.)
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

#define FIT_GROUP_SIZE 64
layout(local_size_x = FIT_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Source { double source[]; };      // #V x 3
layout(std430, binding = 1) readonly buffer Target { double target[]; };      // #V x 3
layout(std430, binding = 2) readonly buffer Offsets { int offsets[]; };       // #F + 1
layout(std430, binding = 3) readonly buffer Indices { int indices[]; };       // corners
layout(std430, binding = 4) writeonly buffer Maps { double maps[]; };         // 16 per face, column-major
layout(std430, binding = 5) writeonly buffer Scales { double scales[]; };     // per corner of the chunk
layout(std430, binding = 6) writeonly buffer Residuals { double residuals[]; };
layout(std430, binding = 7) writeonly buffer Ranks { int ranks[]; };

layout(push_constant) uniform Push {
  uint firstFace;
  uint faceCount;
  double rankThreshold;
} pc;

const int N = 15;
double privateA[N * N];  // row-major: R, then its decomposition
double privateC[N];      // Q^T r, then the solution
double privateRow[N];    // the equation being streamed in
double privateT[16];     // the map, column-major
double privateTau[N];    // Householder factors of the right reflections
int privatePerm[N];      // column permutation of the pivoted QR
#define A(e) privateA[e]
#define tau(e) privateTau[e]
#define perm(e) privatePerm[e]
#define c(e) privateC[e]
#define row(e) privateRow[e]
#define t(e) privateT[e]

dvec3 point(bool fromTarget, int v) {
  return fromTarget ? dvec3(target[3 * v], target[3 * v + 1], target[3 * v + 2])
                    : dvec3(source[3 * v], source[3 * v + 1], source[3 * v + 2]);
}

// Unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix, cyclic Jacobi.
dvec3 smallestEigenvector(dmat3 S) {
  dmat3 Q = dmat3(1.0);
  const double scale = S[0][0] * S[0][0] + S[1][1] * S[1][1] + S[2][2] * S[2][2] +
                       2.0 * (S[0][1] * S[0][1] + S[0][2] * S[0][2] + S[1][2] * S[1][2]);
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = S[0][1] * S[0][1] + S[0][2] * S[0][2] + S[1][2] * S[1][2];
    if (!(off > 1e-34 * scale)) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (S[q][p] == 0.0) continue;
        const double theta = (S[q][q] - S[p][p]) / (2.0 * S[q][p]);
        const double tangent = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(1.0 + theta * theta));
        const double cs = 1.0 / sqrt(1.0 + tangent * tangent);
        const double sn = tangent * cs;
        dmat3 G = dmat3(1.0);
        G[p][p] = cs;
        G[q][q] = cs;
        G[q][p] = sn;   // column q, row p
        G[p][q] = -sn;  // column p, row q
        S = transpose(G) * S * G;
        Q = Q * G;
      }
    }
  }
  int smallest = 0;
  if (S[1][1] < S[smallest][smallest]) smallest = 1;
  if (S[2][2] < S[smallest][smallest]) smallest = 2;
  return normalize(Q[smallest]);
}

// Centroid and unit normal of the least-squares plane of the face's corners; a zero
// normal (no projection) for fewer than four corners, which are always planar.
void bestFitPlane(bool fromTarget, int begin, int k, out dvec3 center, out dvec3 normal) {
  center = dvec3(0.0);
  for (int i = 0; i < k; ++i) center += point(fromTarget, indices[begin + i]);
  center /= double(k);
  normal = dvec3(0.0);
  if (k < 4) return;
  dmat3 covariance = dmat3(0.0);
  for (int i = 0; i < k; ++i) {
    const dvec3 d = point(fromTarget, indices[begin + i]) - center;
    covariance += outerProduct(d, d);
  }
  normal = smallestEigenvector(covariance);
}

dvec3 projected(dvec3 x, dvec3 center, dvec3 normal) { return x - normal * dot(x - center, normal); }

// Givens-rotate `row` (with right-hand side beta) into the triangular factor A, c.
void streamRow(double beta) {
  for (int j = 0; j < N; ++j) {
    if (row(j) == 0.0) continue;
    const double rjj = A(j * N + j);
    const double h = sqrt(rjj * rjj + row(j) * row(j));
    const double cs = rjj / h;
    const double sn = row(j) / h;
    for (int l = j; l < N; ++l) {
      const double x = A(j * N + l);
      const double y = row(l);
      A(j * N + l) = cs * x + sn * y;
      row(l) = cs * y - sn * x;
    }
    const double x = c(j);
    c(j) = cs * x + sn * beta;
    beta = cs * beta - sn * x;
  }
}

// Fill `row` with the equation of corner (p, 1), coordinate j, and return its right-hand
// side for the correction from the identity: r = q_j - p_j.
double equation(dvec3 p, dvec3 q, int j) {
  const dvec4 ph = dvec4(p, 1.0);
  for (int l = 0; l < N; ++l) row(l) = 0.0;
  for (int r = 0; r < 4; ++r) row(4 * j + r) = ph[r];
  for (int r = 0; r < 3; ++r) row(12 + r) = -q[j] * ph[r];
  return q[j] - p[j];
}

// Householder QR with column pivoting of A (in place, R in the upper triangle), applied
// to c as well; returns the numerical rank.
int pivotedQr(double threshold) {
  for (int j = 0; j < N; ++j) perm(j) = j;
  double maxPivot = 0.0;
  for (int k = 0; k < N; ++k) {
    // Pivot: the remaining column of largest norm (recomputed, not downdated: n is small).
    int best = k;
    double bestNorm2 = -1.0;
    for (int j = k; j < N; ++j) {
      double s = 0.0;
      for (int i = k; i < N; ++i) s += A(i * N + j) * A(i * N + j);
      if (s > bestNorm2) {
        bestNorm2 = s;
        best = j;
      }
    }
    if (best != k) {
      for (int i = 0; i < N; ++i) {
        const double x = A(i * N + k);
        A(i * N + k) = A(i * N + best);
        A(i * N + best) = x;
      }
      const int p = perm(k);
      perm(k) = perm(best);
      perm(best) = p;
    }
    const double norm = sqrt(bestNorm2);
    if (norm == 0.0) break;  // the remaining columns are exactly zero
    const double x0 = A(k * N + k);
    const double beta = x0 >= 0.0 ? -norm : norm;
    const double scale = 1.0 / (x0 - beta);
    const double h = (beta - x0) / beta;
    // v = (1, A(k+1..)[k] * scale); apply I - h v v^T to the columns right of k and to c.
    for (int j = k + 1; j < N; ++j) {
      double w = A(k * N + j);
      for (int i = k + 1; i < N; ++i) w += A(i * N + k) * scale * A(i * N + j);
      w *= h;
      A(k * N + j) -= w;
      for (int i = k + 1; i < N; ++i) A(i * N + j) -= w * A(i * N + k) * scale;
    }
    double w = c(k);
    for (int i = k + 1; i < N; ++i) w += A(i * N + k) * scale * c(i);
    w *= h;
    c(k) -= w;
    for (int i = k + 1; i < N; ++i) c(i) -= w * A(i * N + k) * scale;
    A(k * N + k) = beta;
    for (int i = k + 1; i < N; ++i) A(i * N + k) = 0.0;
    maxPivot = max(maxPivot, abs(beta));
  }
  int rank = 0;
  for (int k = 0; k < N; ++k) {
    if (abs(A(k * N + k)) > threshold * maxPivot) ++rank;
  }
  return rank;
}

// Minimum-norm solution of the rank-r system [R11 R12] x = c[0..r): reflections from the
// right turn [R11 R12] into [T 0] = [R11 R12] H_{r-1} ... H_0; then x = H_{r-1} ... H_0
// (T^{-1} c, 0). Leaves the solution, in pivoted order, in c.
void minimumNormSolve(int rank) {
  for (int k = rank - 1; k >= 0; --k) {
    // Reflection acting on columns {k, rank..N-1} that zeroes A(k)[rank..N-1].
    double tail2 = 0.0;
    for (int l = rank; l < N; ++l) tail2 += A(k * N + l) * A(k * N + l);
    tau(k) = 0.0;
    if (tail2 == 0.0) continue;
    const double x0 = A(k * N + k);
    const double beta = x0 >= 0.0 ? -sqrt(x0 * x0 + tail2) : sqrt(x0 * x0 + tail2);
    const double scale = 1.0 / (x0 - beta);
    tau(k) = (beta - x0) / beta;
    for (int l = rank; l < N; ++l) A(k * N + l) *= scale;  // v = (1, tail * scale), kept in place
    for (int i = 0; i < k; ++i) {
      double w = A(i * N + k);
      for (int l = rank; l < N; ++l) w += A(k * N + l) * A(i * N + l);
      w *= tau(k);
      A(i * N + k) -= w;
      for (int l = rank; l < N; ++l) A(i * N + l) -= w * A(k * N + l);
    }
    A(k * N + k) = beta;
  }
  // Back substitution T y = c[0..r), then y is padded with zeros.
  for (int k = rank - 1; k >= 0; --k) {
    double s = c(k);
    for (int l = k + 1; l < rank; ++l) s -= A(k * N + l) * c(l);
    c(k) = s / A(k * N + k);
  }
  for (int l = rank; l < N; ++l) c(l) = 0.0;
  for (int k = 0; k < rank; ++k) {
    if (tau(k) == 0.0) continue;
    double w = c(k);
    for (int l = rank; l < N; ++l) w += A(k * N + l) * c(l);
    w *= tau(k);
    c(k) -= w;
    for (int l = rank; l < N; ++l) c(l) -= w * A(k * N + l);
  }
}

void main() {
  GRID_STRIDE_LOOP(i, pc.faceCount) {
    const uint f = pc.firstFace + i;
    const int begin = offsets[f];
    const int k = offsets[f + 1] - begin;
    const int chunkCorner = begin - offsets[pc.firstFace];

    // One call site for both planes keeps the inlined shader (and its JIT time) small.
    dvec3 centers[2], normals[2];
    for (int side = 0; side < 2; ++side) bestFitPlane(side == 1, begin, k, centers[side], normals[side]);
    const dvec3 sourceCentroid = centers[0], sourceNormal = normals[0];
    const dvec3 targetCentroid = centers[1], targetNormal = normals[1];

    for (int l = 0; l < N * N; ++l) A(l) = 0.0;
    for (int l = 0; l < N; ++l) c(l) = 0.0;
    for (int corner = 0; corner < k; ++corner) {
      const int v = indices[begin + corner];
      const dvec3 p = projected(point(false, v), sourceCentroid, sourceNormal);
      const dvec3 q = projected(point(true, v), targetCentroid, targetNormal);
      for (int j = 0; j < 3; ++j) streamRow(equation(p - sourceCentroid, q - targetCentroid, j));
    }

    const int rank = pivotedQr(pc.rankThreshold);
    minimumNormSolve(rank);
    for (int l = 0; l < 16; ++l) t(l) = 0.0;
    for (int l = 0; l < N; ++l) t(perm(l)) = c(l);
    t(0) += 1.0;
    t(5) += 1.0;
    t(10) += 1.0;
    t(15) = 1.0;

    // Back to the original coordinates: T = S_p T' S_q^{-1}, where (p, 1) S_p = (p - c_p, 1)
    // replaces row 3 by T'[3, :] - c_p . T'[0..2, :], and S_q^{-1} adds c_qj T[:, 3] to
    // column j < 3. T keeps T''s scale: mean reciprocal scale 1 (LocalFit.h says why).
    for (int col = 0; col < 4; ++col) {
      t(4 * col + 3) -= dot(sourceCentroid, dvec3(t(4 * col), t(4 * col + 1), t(4 * col + 2)));
    }
    for (int j = 0; j < 3; ++j) {
      for (int r = 0; r < 4; ++r) t(4 * j + r) += targetCentroid[j] * t(12 + r);
    }

    const dvec4 column3 = dvec4(t(12), t(13), t(14), t(15));
    double squaredResidual = 0.0;
    for (int corner = 0; corner < k; ++corner) {
      const int v = indices[begin + corner];
      const dvec4 ph = dvec4(projected(point(false, v), sourceCentroid, sourceNormal), 1.0);
      const dvec3 q = projected(point(true, v), targetCentroid, targetNormal);
      const double shat = dot(ph, column3);
      scales[chunkCorner + corner] = shat;
      for (int j = 0; j < 3; ++j) {
        const double e = dot(ph, dvec4(t(4 * j), t(4 * j + 1), t(4 * j + 2), t(4 * j + 3))) - q[j] * shat;
        squaredResidual += e * e;
      }
    }
    for (int l = 0; l < 16; ++l) maps[16 * i + l] = t(l);
    residuals[i] = k > 0 ? sqrt(squaredResidual / double(3 * k)) : 0.0;
    ranks[i] = rank;
  }
}
