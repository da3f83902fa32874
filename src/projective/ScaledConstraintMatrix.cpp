#include "projective/ScaledConstraintMatrix.h"

#include <algorithm>
#include <string>

#include "core/Error.h"

namespace plano::projective {

ScaledConstraintMatrix::ScaledConstraintMatrix(Index rows, Index faces, const std::vector<Term>& terms)
    : C_(rows, 4 * faces) {
  // The pattern from triplets whose values name their term and coefficient (id + 1, exact
  // in a double): setFromTriplets sums duplicates, which a count of stored entries reveals.
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(4 * terms.size());
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const Term& term = terms[t];
    if (term.row < 0 || term.row >= rows || term.face < 0 || term.face >= faces || term.scale < 0) {
      throwUsage("constraint matrix: term " + std::to_string(t) + " (row " + std::to_string(term.row) + ", face " +
                 std::to_string(term.face) + ", scale " + std::to_string(term.scale) + ") lies outside a " +
                 std::to_string(rows) + "-row matrix on " + std::to_string(faces) + " faces");
    }
    scaleCount_ = std::max(scaleCount_, term.scale + 1);
    for (Index k = 0; k < 4; ++k) entries.emplace_back(term.row, 4 * term.face + k, static_cast<double>(4 * t + k + 1));
  }
  C_.setFromTriplets(entries.begin(), entries.end());
  C_.makeCompressed();
  if (static_cast<std::size_t>(C_.nonZeros()) != entries.size()) {
    throwUsage("constraint matrix: two terms on the same entry (a row with two corners of one face)");
  }
  coefficients_.resize(entries.size());
  scaleOf_.resize(entries.size());
  for (Eigen::Index e = 0; e < C_.nonZeros(); ++e) {
    const auto id = static_cast<std::size_t>(C_.valuePtr()[e]) - 1;
    const Term& term = terms[id / 4];
    coefficients_[e] = term.coefficients[static_cast<Eigen::Index>(id % 4)];
    scaleOf_[e] = term.scale;
  }
}

const compute::SparseMatrix& ScaledConstraintMatrix::fill(std::span<const double> scales) {
  if (static_cast<Index>(scales.size()) < scaleCount_) {
    throwUsage("constraint matrix: " + std::to_string(scales.size()) + " scales for terms that use " +
               std::to_string(scaleCount_));
  }
  double* values = C_.valuePtr();
  for (std::size_t e = 0; e < coefficients_.size(); ++e) values[e] = coefficients_[e] / scales[scaleOf_[e]];
  return C_;
}

}  // namespace plano::projective
