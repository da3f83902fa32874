#include "projective/ScaledConstraintMatrix.h"

#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "compute/Admm.h"
#include "core/Error.h"

namespace plano::projective {
namespace {

using Term = ScaledConstraintMatrix::Term;

/// Rows of two terms on distinct faces (compatibility rows) and of one (positional rows),
/// random coefficients with some exact zeros, scale index = a corner-like slot.
std::vector<Term> randomTerms(Index rows, Index faces, Index scales, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<Index> face(0, faces - 1), scale(0, scales - 1);
  std::uniform_real_distribution<double> value(-2.0, 2.0);
  std::vector<Term> terms;
  for (Index r = 0; r < rows; ++r) {
    const Index a = face(random);
    Eigen::RowVector4d p(value(random), value(random), value(random), 1.0);
    if (r % 5 == 0) p[1] = 0.0;  // a base vertex on a coordinate plane
    terms.push_back({r, a, p, scale(random)});
    if (r % 3 != 0) terms.push_back({r, (a + 1 + r % (faces - 1)) % faces, -p, scale(random)});
  }
  return terms;
}

compute::SparseMatrix assembled(Index rows, Index faces, const std::vector<Term>& terms, const std::vector<double>& scales) {
  std::vector<Eigen::Triplet<double>> entries;
  for (const Term& t : terms) {
    for (Index k = 0; k < 4; ++k) entries.emplace_back(t.row, 4 * t.face + k, t.coefficients[k] / scales[t.scale]);
  }
  compute::SparseMatrix C(rows, 4 * faces);
  C.setFromTriplets(entries.begin(), entries.end());
  return C;
}

TEST(ScaledConstraintMatrix, FilledValuesEqualTheAssembledMatrixOnOneFixedPattern) {
  const Index rows = 40, faces = 12, scales = 30;
  const std::vector<Term> terms = randomTerms(rows, faces, scales, 3);
  ScaledConstraintMatrix matrix(rows, faces, scales, terms);
  std::mt19937 random(4);
  std::uniform_real_distribution<double> scale(0.5, 1.5);
  compute::SparseMatrix first;
  for (int step = 0; step < 3; ++step) {
    std::vector<double> s(scales);
    for (double& v : s) v = scale(random);
    const compute::SparseMatrix& C = matrix.fill(s);
    const compute::SparseMatrix expected = assembled(rows, faces, terms, s);
    ASSERT_EQ(C.nonZeros(), static_cast<Eigen::Index>(4 * terms.size()));  // zero coefficients stored too
    EXPECT_EQ(compute::SparseMatrix(C - expected).cwiseAbs().sum(), 0.0) << "step " << step;
    if (step == 0) first = C;
    EXPECT_TRUE(compute::sameSparsityPattern(C, first));
  }
}

TEST(ScaledConstraintMatrix, BadTermsAndAWrongScaleCountAreUsageErrors) {
  const Eigen::RowVector4d p(1.0, 2.0, 3.0, 1.0);
  auto kindOf = [](auto&& make) -> std::optional<ErrorKind> {
    try {
      make();
    } catch (const Error& e) {
      return e.kind();
    }
    return std::nullopt;
  };
  EXPECT_EQ(kindOf([&] { ScaledConstraintMatrix(2, 2, 4, {{0, 0, p, 0}, {0, 0, -p, 1}}); }), ErrorKind::Usage);
  EXPECT_EQ(kindOf([&] { ScaledConstraintMatrix(2, 2, 4, {{2, 0, p, 0}}); }), ErrorKind::Usage);
  EXPECT_EQ(kindOf([&] { ScaledConstraintMatrix(2, 2, 4, {{0, 2, p, 0}}); }), ErrorKind::Usage);
  EXPECT_EQ(kindOf([&] { ScaledConstraintMatrix(2, 2, 4, {{0, 0, p, -1}}); }), ErrorKind::Usage);
  EXPECT_EQ(kindOf([&] { ScaledConstraintMatrix(2, 2, 4, {{0, 0, p, 4}}); }), ErrorKind::Usage);
  ScaledConstraintMatrix matrix(2, 2, 4, {{0, 0, p, 0}, {1, 1, p, 3}});
  EXPECT_EQ(matrix.scaling().scaleCount, 4);
  const std::vector<double> three(3, 1.0), four(4, 2.0);
  EXPECT_EQ(kindOf([&] { matrix.fill(three); }), ErrorKind::Usage);
  EXPECT_DOUBLE_EQ(matrix.fill(four).coeff(1, 5), 1.0);
}

}  // namespace
}  // namespace plano::projective
