#include "core/ParallelFor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/Error.h"
#include "support/ScopedEnvironment.h"

namespace plano {
namespace {

/// Returns to the default thread count after each test: the suite may run in one process.
class ParallelFor : public ::testing::Test {
 protected:
  void TearDown() override { setCpuThreads(0); }
};

TEST_F(ParallelFor, EveryItemIsVisitedOnceInContiguousChunksWhateverTheThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    SCOPED_TRACE(threads);
    setCpuThreads(threads);
    std::vector<int> visits(10007, 0);
    std::mutex mutex;
    std::vector<std::pair<std::ptrdiff_t, std::ptrdiff_t>> chunks;
    parallelFor(static_cast<std::ptrdiff_t>(visits.size()), 1, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (std::ptrdiff_t i = begin; i < end; ++i) ++visits[static_cast<std::size_t>(i)];
      const std::lock_guard<std::mutex> lock(mutex);
      chunks.emplace_back(begin, end);
    });
    EXPECT_EQ(std::count(visits.begin(), visits.end(), 1), static_cast<std::ptrdiff_t>(visits.size()));
    EXPECT_EQ(chunks.size(), static_cast<std::size_t>(threads));
  }
}

TEST_F(ParallelFor, LessWorkThanTwoMinimumChunksRunsOnTheCallingThreadAlone) {
  setCpuThreads(8);
  std::vector<std::thread::id> runners;
  parallelFor(1000, 512, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    EXPECT_EQ(begin, 0);
    EXPECT_EQ(end, 1000);
    runners.push_back(std::this_thread::get_id());
  });
  ASSERT_EQ(runners.size(), 1u);
  EXPECT_EQ(runners.front(), std::this_thread::get_id());
  int calls = 0;
  parallelFor(0, 1, [&](std::ptrdiff_t, std::ptrdiff_t) { ++calls; });
  EXPECT_EQ(calls, 0) << "no items, no call";
}

TEST_F(ParallelFor, AChunksExceptionIsRethrownOnceEveryChunkHasFinished) {
  setCpuThreads(4);
  std::vector<int> visits(4000, 0);
  try {
    parallelFor(4000, 1, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (std::ptrdiff_t i = begin; i < end; ++i) ++visits[static_cast<std::size_t>(i)];
      if (begin > 0) throw std::runtime_error("chunk from " + std::to_string(begin));
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "chunk from 1000") << "the lowest chunk's";
  }
  EXPECT_EQ(std::count(visits.begin(), visits.end(), 1), 4000) << "the other chunks ran to their end";
}

TEST_F(ParallelFor, NestedConcurrentAndRepeatedCallsEachVisitEveryItemOnce) {
  setCpuThreads(3);
  // Calls from inside a chunk (on the calling thread and on the pool's) while the pool
  // runs their outer call.
  constexpr std::ptrdiff_t kOuter = 6, kInner = 3000;
  std::vector<std::vector<int>> visits(kOuter, std::vector<int>(kInner, 0));
  parallelFor(kOuter, 1, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    for (std::ptrdiff_t i = begin; i < end; ++i) {
      auto& row = visits[static_cast<std::size_t>(i)];
      parallelFor(kInner, 1, [&](std::ptrdiff_t b, std::ptrdiff_t e) {
        for (std::ptrdiff_t j = b; j < e; ++j) ++row[static_cast<std::size_t>(j)];
      });
    }
  });
  for (const auto& row : visits) EXPECT_EQ(std::count(row.begin(), row.end(), 1), kInner);

  // Calls from several threads at once (one gets the pool, the others threads of their
  // own), each many times in a row.
  constexpr int kCallers = 4, kRepeats = 200;
  std::vector<std::vector<int>> sums(kCallers, std::vector<int>(1000, 0));
  std::vector<std::thread> callers;
  for (int c = 0; c < kCallers; ++c) {
    callers.emplace_back([&sums, c] {
      auto& mine = sums[static_cast<std::size_t>(c)];
      for (int r = 0; r < kRepeats; ++r) {
        parallelFor(static_cast<std::ptrdiff_t>(mine.size()), 1, [&](std::ptrdiff_t b, std::ptrdiff_t e) {
          for (std::ptrdiff_t j = b; j < e; ++j) ++mine[static_cast<std::size_t>(j)];
        });
      }
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (const auto& mine : sums) EXPECT_EQ(std::count(mine.begin(), mine.end(), kRepeats), 1000);
}

TEST_F(ParallelFor, TheThreadCountIsTheChosenOneElsePlanoThreadsElseEveryCore) {
  if (std::getenv("PLANO_THREADS") == nullptr) {
    EXPECT_EQ(cpuThreads(), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  }
  const test::ScopedEnvironment environment("PLANO_THREADS", "3");
  EXPECT_EQ(cpuThreads(), 3);
  setCpuThreads(2);
  EXPECT_EQ(cpuThreads(), 2);
  setCpuThreads(0);
  EXPECT_EQ(cpuThreads(), 3);
}

TEST_F(ParallelFor, AMalformedPlanoThreadsOrANegativeCountIsAUsageErrorThatNamesIt) {
  for (const char* value : {"abc", "0", "-2", "4x", "100000"}) {
    SCOPED_TRACE(value);
    const test::ScopedEnvironment environment("PLANO_THREADS", value);
    try {
      cpuThreads();
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage);
      EXPECT_NE(std::string(e.what()).find("PLANO_THREADS"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(setCpuThreads(-1), Error);
  EXPECT_THROW(setCpuThreads(5000), Error);
}

}  // namespace
}  // namespace plano
