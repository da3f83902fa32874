// plano generate's estimate of the mesh it would build (plano/GenerateSize.h): a resolution
// whose mesh cannot fit is refused up front with the estimate, as subdivide --levels is.
#include "plano/GenerateSize.h"

#include <gtest/gtest.h>

#include "mesh/Generators.h"

namespace plano::cli {
namespace {

constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;

TEST(GenerateSize, ADomeThatCannotFitIsRefusedWithTheEstimate) {
  // hexdome -n 4096 was killed by the kernel at ~24 GiB.
  try {
    requireGeneratable("hexdome", 4096, 8 * kGiB);
    FAIL() << "hexdome -n 4096 was accepted in 8 GiB";
  } catch (const OutOfMemory& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("generating hexdome -n 4096 (50343937 faces) needs"), std::string::npos) << message;
    EXPECT_NE(message.find("GiB allowed"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(requireGeneratable("hexdome", 100, 8 * kGiB));
  EXPECT_THROW(requireGeneratable("translational", 4096, kGiB), OutOfMemory);
  EXPECT_NO_THROW(requireGeneratable("cube", 4096, kGiB));
}

TEST(GenerateSize, FaceCountsAreThoseOfTheGenerators) {
  for (const auto& kind : generate::generatorKinds()) {
    for (const Index n : {2, 5}) {
      EXPECT_EQ(generatedSize(kind.name, n).faces, static_cast<double>(generate::byName(kind.name, n).faceCount()))
          << kind.name << " -n " << n;
    }
  }
}

TEST(GenerateSize, AResolutionBelowTheKindsLeastIsAUsageErrorNamingIt) {
  try {
    requireGeneratable("revolution", 1);
    FAIL() << "revolution -n 1 was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_STREQ(e.what(), "generate revolution: -n must be at least 2 (got 1)");
  }
  EXPECT_THROW(requireGeneratable("translational", 0), Error);
  EXPECT_NO_THROW(requireGeneratable("hexplane", 0));
}

}  // namespace
}  // namespace plano::cli
