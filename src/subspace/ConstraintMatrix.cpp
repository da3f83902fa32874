#include "subspace/ConstraintMatrix.h"

#include <algorithm>
#include <string>

#include "core/Error.h"
#include "subspace/FaceConstraintBlocks.h"

namespace plano::subspace {

Index ConstraintMatrix::equationCount() const {
  return static_cast<Index>(matrix.rows()) * (separable ? 3 : 1);
}

compute::SparseMatrix ConstraintMatrix::fullMatrix() const {
  if (!separable) return matrix;
  // B = B1 (x) I3: row 3 r + c holds row r's entries at columns 3 j + c, still sorted, so the
  // compressed rows are written directly.
  const Eigen::Index rows = matrix.rows() * 3;
  compute::SparseMatrix full(rows, matrix.cols() * 3);
  full.resizeNonZeros(matrix.nonZeros() * 3);
  int* outer = full.outerIndexPtr();
  int* inner = full.innerIndexPtr();
  double* values = full.valuePtr();
  int next = 0;
  outer[0] = 0;
  for (int r = 0; r < matrix.outerSize(); ++r) {
    for (int c = 0; c < 3; ++c) {
      for (compute::SparseMatrix::InnerIterator it(matrix, r); it; ++it) {
        inner[next] = 3 * static_cast<int>(it.col()) + c;
        values[next] = it.value();
        ++next;
      }
      outer[3 * r + c + 1] = next;
    }
  }
  return full;
}

double ConstraintMatrix::residual(const Positions& X) const {
  if (separable) return (matrix * X).norm();
  const Eigen::Map<const Eigen::VectorXd> x(X.data(), X.size());
  return (matrix * x).norm();
}

Index ConstraintMatrix::horizontalFaceCount() const {
  Index count = 0;
  for (std::size_t f = 0; f < assigned.size(); ++f)
    count += assigned[f] == FaceSpace::Vertical && effective[f] == FaceSpace::Parallel ? 1 : 0;
  return count;
}

ConstraintMatrix buildConstraintMatrix(const PolygonMesh& Y, std::span<const FaceSpace> spaces,
                                       const ConstraintSettings& settings) {
  const Index nf = Y.faceCount(), nv = Y.vertexCount();
  if (static_cast<Index>(spaces.size()) != nf) {
    throwBadInput("face assignment has " + std::to_string(spaces.size()) + " entries for a mesh of " +
                  std::to_string(nf) + " faces");
  }
  if (!(settings.up.norm() > 0.0) || !settings.up.allFinite()) throwUsage("the up vector must be finite and non-zero");
  ConstraintMatrix B;
  B.vertexCount = nv;
  B.assigned.assign(spaces.begin(), spaces.end());
  B.effective = B.assigned;
  B.separable = true;
  for (FaceSpace s : spaces) B.separable = B.separable && s == FaceSpace::Affine;

  std::vector<Eigen::Triplet<double>> triplets;
  B.faceRowOffsets.assign(static_cast<std::size_t>(nf) + 1, 0);
  Index row = 0;
  for (Index f = 0; f < nf; ++f) {
    const auto face = Y.faces[f];
    for (Index v : face) {
      if (v < 0 || v >= nv) throwBadInput("face " + std::to_string(f) + " refers to vertex " + std::to_string(v));
    }
    const Index k = Y.faces.degree(f);
    B.faceRowOffsets[f] = row;
    if (k == 3 && spaces[f] == FaceSpace::Affine) continue;  // Triangles are always affine images.
    const FaceFrame frame = fitFaceFrame(Y.vertices, face, f, settings.degeneracy);
    B.maxNonPlanarity = std::max(B.maxNonPlanarity, frame.nonPlanarity);
    Eigen::MatrixXd block;
    if (B.separable) {
      block = affineFaceBlock(frame);
      for (Eigen::Index r = 0; r < block.rows(); ++r)
        for (Index i = 0; i < k; ++i) triplets.emplace_back(row + r, face[i], block(r, i));
      row += static_cast<Index>(block.rows());
      continue;
    }
    FaceSpace space = spaces[f];
    if (space == FaceSpace::Vertical && isHorizontal(frame, settings.up, settings.horizontalTolerance)) {
      space = FaceSpace::Parallel;
    }
    B.effective[f] = space;
    block = faceBlock(frame, space, settings.up);
    for (Eigen::Index r = 0; r < block.rows(); ++r)
      for (Index i = 0; i < k; ++i)
        for (int c = 0; c < 3; ++c) {
          const double value = block(r, 3 * i + c);
          if (value != 0.0) triplets.emplace_back(row + r, 3 * face[i] + c, value);
        }
    row += static_cast<Index>(block.rows());
  }
  B.faceRowOffsets[nf] = row;
  B.matrix.resize(row, B.separable ? nv : 3 * nv);
  B.matrix.setFromTriplets(triplets.begin(), triplets.end());  // Duplicates (repeated vertices) are summed.
  return B;
}

}  // namespace plano::subspace
