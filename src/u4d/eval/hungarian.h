// Optimal one-to-one assignment (the Hungarian / Kuhn-Munkres method).
//
// Used by the metrics to match predicted to ground-truth objects (instances
// by IoU, people by joint distance, meshes by Chamfer distance) so that a
// score never depends on the order or the ids of the prediction.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace u4d::eval {

// Minimum-cost assignment for a rows x cols cost matrix (rectangular allowed).
// Returns `row_to_col` of size rows: the column assigned to each row, or -1
// when rows > cols and the row is left over. Exactly min(rows, cols) pairs are
// assigned and their total cost is minimal. O(n^2 m) with n = min, m = max.
// Throws u4d::Error when a cost is not finite (use a large finite value for
// "forbidden" pairs). An empty matrix gives an empty / all -1 result.
std::vector<int> MinCostAssignment(const Eigen::MatrixXd& cost);

// Maximum-score assignment: MinCostAssignment(-score).
std::vector<int> MaxScoreAssignment(const Eigen::MatrixXd& score);

}  // namespace u4d::eval
