// The condition of the loops the device runs without the host (gpu/system/loop_condition.hpp):
// both systems call it after each run of a loop's body, so its runs, its cap and its reset are
// what the CPU and the CUDA backends do.
#include "gpu/system/loop_condition.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace galpha::detail {
namespace {

// Runs a body that lowers `count` by `step` (not below zero) the way ReplayWhile does: once, then
// again while the condition says so. Returns the number of runs.
uint32_t RunLoop(uint32_t* count, uint32_t step, const WhileCountNonzero& condition) {
  uint32_t runs = 0;
  do {
    *count = *count > step ? *count - step : 0;
    ++runs;
  } while (condition());
  return runs;
}

TEST(LoopConditionTest, RunsUntilTheCountIsZeroAndResetsItsRuns) {
  uint32_t count = 10, runs = 0;
  int32_t capped = 0;
  const WhileCountNonzero condition{&count, &runs, 100, &capped};
  EXPECT_EQ(RunLoop(&count, 3, condition), 4u);  // 10 -> 7 -> 4 -> 1 -> 0
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(runs, 0u) << "the next loop starts from zero runs";
  EXPECT_EQ(capped, 0);

  count = 5;
  EXPECT_EQ(RunLoop(&count, 5, condition), 1u) << "the body runs at least once";
  EXPECT_EQ(runs, 0u);
  EXPECT_EQ(capped, 0);
}

TEST(LoopConditionTest, CapEndsALoopThatDoesNotFinishAndSaysSo) {
  uint32_t count = 1000, runs = 0;
  int32_t capped = 0;
  const WhileCountNonzero condition{&count, &runs, 7, &capped};
  EXPECT_EQ(RunLoop(&count, 1, condition), 7u);
  EXPECT_EQ(count, 993u);
  EXPECT_EQ(capped, 1);
  EXPECT_EQ(runs, 0u);
}

TEST(LoopConditionTest, ALoopThatFinishesOnItsLastAllowedRunIsNotCapped) {
  uint32_t count = 7, runs = 0;
  int32_t capped = 0;
  const WhileCountNonzero condition{&count, &runs, 7, &capped};
  EXPECT_EQ(RunLoop(&count, 1, condition), 7u);
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(capped, 0);
}

}  // namespace
}  // namespace galpha::detail
