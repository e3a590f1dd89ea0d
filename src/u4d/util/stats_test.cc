#include "u4d/util/stats.h"

#include <gtest/gtest.h>

namespace u4d {
namespace {

TEST(StatsTest, MedianOfMiddleAveragesTheMiddleTwoOfAnEvenCount) {
  EXPECT_EQ(MedianOfMiddle({}), 0.0);
  EXPECT_EQ(MedianOfMiddle({3.0}), 3.0);
  EXPECT_EQ(MedianOfMiddle({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(MedianOfMiddle({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_DOUBLE_EQ(MedianOfMiddle({0.9, 0.8, 0.1, 0.85, 0.0, 0.95, 0.82, 0.88}), 0.835);
  // Median keeps the upper one.
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 3.0);
}

}  // namespace
}  // namespace u4d
