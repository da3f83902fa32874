#version 450
// Batched closest ideal maps (projective-maps paper, App. A), the math of
// src/projective/IdealMapFit.cpp: per face, the rigid or similarity map closest to its
// fitted projective map T. The linear part is the fit's Jacobian J at the source centroid
// restricted to the face plane (the plane basis e1, e2 to e1 J, e2 J, the normal to the
// unit normal of their span scaled like the plane), its closest rotation R (procrustes.glsl),
// the similarity scale the mean in-plane singular value, the translation the centroid's
// image. A fit that sends the centroid or a corner through the plane at infinity falls
// back, when target corners are bound, to Kabsch / Umeyama between the corner sets; without
// them, a centroid at infinity is reported (method 2) and its map left the identity.
//
// One invocation per face. (`centroid` is a GLSL keyword: the code says faceCentre.)
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "procrustes.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Source { double source[]; };  // #V x 3
layout(std430, binding = 1) readonly buffer Target { double target[]; };  // #V x 3 (read only with hasTarget)
layout(std430, binding = 2) readonly buffer Offsets { int offsets[]; };   // #F + 1
layout(std430, binding = 3) readonly buffer Indices { int indices[]; };   // corners
layout(std430, binding = 4) readonly buffer Fitted { double fitted[]; };  // 16 per face of the chunk, column-major
layout(std430, binding = 5) writeonly buffer Ideal { double ideal[]; };   // 16 per face of the chunk, column-major
layout(std430, binding = 6) writeonly buffer Methods { int methods[]; };  // per face of the chunk (compute::IdealMapMethod)

layout(push_constant) uniform Push {
  uint firstFace;
  uint faceCount;  // faces in this dispatch
  uint hasTarget;
  uint similar;
} pc;

dvec3 sourceAt(int v) { return dvec3(source[3 * v], source[3 * v + 1], source[3 * v + 2]); }
dvec3 targetAt(int v) { return dvec3(target[3 * v], target[3 * v + 1], target[3 * v + 2]); }

bool finite4(dvec4 h) { return !any(isnan(h)) && !any(isinf(h)); }

// Eigenvectors (columns of V) and eigenvalues of a symmetric 3x3 matrix, cyclic Jacobi.
void symmetricEigen(dmat3 A, out dmat3 V, out dvec3 values) {
  V = dmat3(1.0);
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = A[1][0] * A[1][0] + A[2][0] * A[2][0] + A[2][1] * A[2][1];
    const double diagonal = A[0][0] * A[0][0] + A[1][1] * A[1][1] + A[2][2] * A[2][2];
    if (!(off > 1e-32LF * diagonal)) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        const double apq = A[q][p];
        if (apq == 0.0LF) continue;
        const double theta = (A[q][q] - A[p][p]) / (2.0LF * apq);
        const double t = (theta >= 0.0LF ? 1.0LF : -1.0LF) / (abs(theta) + sqrt(theta * theta + 1.0LF));
        const double c = 1.0LF / sqrt(t * t + 1.0LF);
        const double s = t * c;
        dmat3 J = dmat3(1.0);
        J[p][p] = c;
        J[q][q] = c;
        J[q][p] = s;   // row p, column q
        J[p][q] = -s;  // row q, column p
        A = transpose(J) * A * J;
        V = V * J;
      }
    }
  }
  values = dvec3(A[0][0], A[1][1], A[2][2]);
}

void writeMap(uint i, dmat3 M, dvec3 t) {
  for (int col = 0; col < 3; ++col) {
    for (int r = 0; r < 3; ++r) ideal[16 * i + 4 * col + r] = M[col][r];
    ideal[16 * i + 4 * col + 3] = t[col];
  }
  ideal[16 * i + 12] = 0.0LF;
  ideal[16 * i + 13] = 0.0LF;
  ideal[16 * i + 14] = 0.0LF;
  ideal[16 * i + 15] = 1.0LF;
}

void main() {
  GRID_STRIDE_LOOP(i, pc.faceCount) {
    const uint f = pc.firstFace + i;
    const int begin = offsets[f];
    const int end = offsets[f + 1];
    dmat4 T;
    for (int col = 0; col < 4; ++col) {
      for (int r = 0; r < 4; ++r) T[col][r] = fitted[16 * i + 4 * col + r];
    }
    dvec3 faceCentre = dvec3(0.0);
    for (int j = begin; j < end; ++j) faceCentre += sourceAt(indices[j]);
    faceCentre /= double(end - begin);

    bool fallback = false;
    if (pc.hasTarget != 0u) {
      const double w = dot(dvec4(faceCentre, 1.0), T[3]);
      fallback = !(abs(w) > 1e-12LF) || isnan(w) || isinf(w);
      for (int j = begin; j < end && !fallback; ++j) {
        if (!(dot(dvec4(sourceAt(indices[j]), 1.0), T[3]) * w > 0.0LF)) fallback = true;
      }
    }

    dvec3 image;
    dmat3 L;
    double similarityScale = 1.0LF;
    double spread = 1.0LF;
    if (fallback) {
      image = dvec3(0.0);
      for (int j = begin; j < end; ++j) image += targetAt(indices[j]);
      image /= double(end - begin);
      L = dmat3(0.0);
      spread = 0.0LF;
      for (int j = begin; j < end; ++j) {
        const dvec3 p = sourceAt(indices[j]) - faceCentre;
        L += outerProduct(p, targetAt(indices[j]) - image);
        spread += dot3(p, p);
      }
    } else {
      const dvec4 h = dvec4(faceCentre, 1.0) * T;
      if (!(abs(h.w) > 1e-12LF) || !finite4(h)) {
        writeMap(i, dmat3(1.0), dvec3(0.0));
        methods[i] = 2;
        continue;
      }
      dmat3 covariance = dmat3(0.0);
      for (int j = begin; j < end; ++j) {
        const dvec3 p = sourceAt(indices[j]) - faceCentre;
        covariance += outerProduct(p, p);
      }
      dmat3 V;
      dvec3 values;
      symmetricEigen(covariance, V, values);
      // The plane basis: the two largest eigenvalues' vectors (the linear map below does
      // not depend on which orthonormal basis of the plane they are).
      int order[3] = int[3](0, 1, 2);  // eigenvalues descending
      if (values[order[0]] < values[order[1]]) { const int t = order[0]; order[0] = order[1]; order[1] = t; }
      if (values[order[1]] < values[order[2]]) { const int t = order[1]; order[1] = order[2]; order[2] = t; }
      if (values[order[0]] < values[order[1]]) { const int t = order[0]; order[0] = order[1]; order[1] = t; }
      const dvec3 e1 = V[order[0]];
      const dvec3 e2 = V[order[1]];
      const dvec3 n = cross3(e1, e2);

      image = h.xyz / h.w;
      dmat3 J;  // J(k, j) = (T(k, j) - T(k, 3) phi_j) / w, as J[j][k]
      for (int col = 0; col < 3; ++col) {
        for (int r = 0; r < 3; ++r) J[col][r] = (T[col][r] - T[3][r] * image[col]) / h.w;
      }
      const dvec3 a = e1 * J;
      const dvec3 b = e2 * J;
      const dvec3 axb = cross3(a, b);
      const double area = norm3(axb);
      const dvec3 normalImage = area > 1e-300LF ? axb / sqrt(area) : n * J;
      L = outerProduct(e1, a) + outerProduct(e2, b) + outerProduct(n, normalImage);
      similarityScale = 0.5LF * sqrt(dot3(a, a) + dot3(b, b) + 2.0LF * area);
    }

    dmat3 R;
    dvec3 singular;
    closestRotation(L, R, singular);
    double s = 1.0LF;
    if (pc.similar != 0u) {
      s = fallback ? max(singular.x + singular.y + singular.z, 0.0LF) / max(spread, 1e-300LF) : similarityScale;
    }
    const dmat3 M = s * R;
    writeMap(i, M, image - faceCentre * M);
    methods[i] = fallback ? 1 : 0;
  }
}
