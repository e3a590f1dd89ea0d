#include "u4d/eval/hungarian.h"

#include <limits>

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

TEST(Hungarian, BeatsGreedy) {
  // Greedy takes the 1 first and is left with 100 (total 101); optimal is 2 + 2.
  Eigen::MatrixXd cost(2, 2);
  cost << 1, 2, 2, 100;
  EXPECT_EQ(MinCostAssignment(cost), (std::vector<int>{1, 0}));
}

TEST(Hungarian, ThreeByThreeByHand) {
  // Row 0 -> 1 (1), row 1 -> 0 (2), row 2 -> 2 (2): total 5, the unique minimum.
  Eigen::MatrixXd cost(3, 3);
  cost << 4, 1, 3, 2, 0, 5, 3, 2, 2;
  EXPECT_EQ(MinCostAssignment(cost), (std::vector<int>{1, 0, 2}));
}

TEST(Hungarian, Rectangular) {
  Eigen::MatrixXd tall(3, 2);  // rows 0 and 2 get the columns; row 1 is left over
  tall << 1, 5, 9, 9, 5, 1;
  EXPECT_EQ(MinCostAssignment(tall), (std::vector<int>{0, -1, 1}));
  Eigen::MatrixXd wide(2, 3);
  wide << 7, 3, 1, 1, 3, 7;
  EXPECT_EQ(MinCostAssignment(wide), (std::vector<int>{2, 0}));
  EXPECT_EQ(MinCostAssignment(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
}

TEST(Hungarian, MaxScoreAndBadInput) {
  Eigen::MatrixXd score(2, 2);
  score << 0.6, 0.5, 0.5, 0.0;  // greedy 0.6; optimal 0.5 + 0.5
  EXPECT_EQ(MaxScoreAssignment(score), (std::vector<int>{1, 0}));
  score(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(MinCostAssignment(score), Error);
}

}  // namespace
}  // namespace u4d::eval
