#version 450
// The per-face parts of the subspace ASAP/ARAP local step (linear-spaces paper,
// handle-based deformation; compute/ReducedArap.h), one invocation per face, in two modes
// around the batched Procrustes kernel (closest_rotations):
//   mode 0: the covariance M_f = sum_i (x_i - xm)(y_i - ym)^T of the face's centred
//           corners in the current (x) and rest (y) shapes;
//   mode 1: with R_f and the signed singular values of M_f, the scale s_f (ASAP: their sum
//           over sum_i |y_i - ym|^2; ARAP: 1), every corner's target t_i = s_f R_f (y_i - ym)
//           and the face's energy sum_i |x_i - xm - t_i|^2.
// Positions are vec(X) with rows 3 v + c; matrices are column-major, 9 per face. The
// operation order is the host kernels' (subspace/SubspaceDeformation.cpp).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer FaceOffsets { int faceOffsets[]; };
layout(std430, binding = 1) readonly buffer FaceIndices { int faceIndices[]; };
layout(std430, binding = 2) readonly buffer X { double x[]; };
layout(std430, binding = 3) readonly buffer Y { double y[]; };
layout(std430, binding = 4) buffer Covariances { double covariances[]; };
layout(std430, binding = 5) readonly buffer Rotations { double rotations[]; };
layout(std430, binding = 6) readonly buffer Singular { double singular[]; };
layout(std430, binding = 7) writeonly buffer CornerTargets { double cornerTargets[]; };  // 3 per corner
layout(std430, binding = 8) writeonly buffer FaceEnergy { double faceEnergy[]; };

layout(push_constant) uniform Push {
  uint faceCount;
  uint mode;
  uint asap;
} pc;

dvec3 position(uint v) { return dvec3(x[3 * v], x[3 * v + 1], x[3 * v + 2]); }
dvec3 rest(uint v) { return dvec3(y[3 * v], y[3 * v + 1], y[3 * v + 2]); }

void main() {
  GRID_STRIDE_LOOP(f, pc.faceCount) {
    const int begin = faceOffsets[f];
    const int end = faceOffsets[f + 1];
    dvec3 xm = dvec3(0.0), ym = dvec3(0.0);
    for (int i = begin; i < end; ++i) {
      xm += position(uint(faceIndices[i]));
      ym += rest(uint(faceIndices[i]));
    }
    xm /= double(end - begin);
    ym /= double(end - begin);
    if (pc.mode == 0) {
      dmat3 M = dmat3(0.0);
      for (int i = begin; i < end; ++i) {
        const uint v = uint(faceIndices[i]);
        M += outerProduct(position(v) - xm, rest(v) - ym);
      }
      for (int col = 0; col < 3; ++col) {
        for (int r = 0; r < 3; ++r) covariances[9 * f + 3 * col + r] = M[col][r];
      }
    } else {
      dmat3 R;
      for (int col = 0; col < 3; ++col) {
        for (int r = 0; r < 3; ++r) R[col][r] = rotations[9 * f + 3 * col + r];
      }
      double scale = 1.0;
      if (pc.asap != 0) {
        double norm2 = 0.0;
        for (int i = begin; i < end; ++i) {
          const dvec3 d = rest(uint(faceIndices[i])) - ym;
          norm2 += dot(d, d);
        }
        const double sum = singular[3 * f] + singular[3 * f + 1] + singular[3 * f + 2];
        scale = norm2 > 0.0 ? sum / norm2 : 1.0;
      }
      double energy = 0.0;
      for (int i = begin; i < end; ++i) {
        const uint v = uint(faceIndices[i]);
        const dvec3 t = scale * (R * (rest(v) - ym));
        cornerTargets[3 * i] = t.x;
        cornerTargets[3 * i + 1] = t.y;
        cornerTargets[3 * i + 2] = t.z;
        const dvec3 e = position(v) - xm - t;
        energy += dot(e, e);
      }
      faceEnergy[f] = energy;
    }
  }
}
