// compute::DeviceMatrix: host values, negation sharing the source, fetched once, checked.
#include "compute/DeviceMatrix.h"

#include <gtest/gtest.h>

#include "core/Error.h"

namespace plano::compute {
namespace {

/// A source that counts its fetches and can say its values are gone.
class CountingSource final : public DeviceMatrixSource {
 public:
  explicit CountingSource(Eigen::MatrixXd values) : values_(std::move(values)) {}
  void fetch(Eigen::MatrixXd& out) const override {
    ++fetches;
    if (gone) throwUsage("gone");
    out = values_;
  }
  mutable int fetches = 0;
  bool gone = false;

 private:
  Eigen::MatrixXd values_;
};

TEST(DeviceMatrix, ADefaultMatrixIsEmptyOnTheHost) {
  const DeviceMatrix m;
  EXPECT_TRUE(m.onHost());
  EXPECT_EQ(m.values().size(), 0);
  EXPECT_EQ(m.negated().values().size(), 0);
}

TEST(DeviceMatrix, ValuesAreFetchedOnceAndNegationSharesTheSource) {
  const Eigen::MatrixXd values = Eigen::MatrixXd::Random(4, 3);
  auto source = std::make_shared<CountingSource>(values);
  const DeviceMatrix m(4, 3, source);
  EXPECT_FALSE(m.onHost());
  const DeviceMatrix minus = m.negated();
  EXPECT_EQ(minus.source(), m.source());
  EXPECT_EQ(minus.factor(), -1.0);
  EXPECT_EQ(m.values(), values);
  EXPECT_EQ(m.values(), values);
  EXPECT_EQ(source->fetches, 1);
  EXPECT_TRUE(m.onHost());
  EXPECT_EQ(minus.values(), -values);  // a copy of its own: one more fetch
  EXPECT_EQ(source->fetches, 2);
  EXPECT_EQ(m.negated().values(), -values);  // negating fetched values copies nothing
  EXPECT_EQ(source->fetches, 2);
}

TEST(DeviceMatrix, ASourceOfOtherSizeOrGoneIsAUsageError) {
  auto source = std::make_shared<CountingSource>(Eigen::MatrixXd::Zero(2, 2));
  EXPECT_THROW((void)DeviceMatrix(3, 2, source).values(), Error);
  source->gone = true;
  EXPECT_THROW((void)DeviceMatrix(2, 2, source).values(), Error);
  EXPECT_THROW(DeviceMatrix(2, 2, nullptr), Error);
}

}  // namespace
}  // namespace plano::compute
