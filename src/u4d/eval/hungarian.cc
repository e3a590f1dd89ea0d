#include "u4d/eval/hungarian.h"

#include <limits>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

// Shortest augmenting path with potentials (Jonker-Volgenant style) for
// n <= m: assigns every row of an n x m matrix. Indices are 1-based inside.
std::vector<int> AssignRows(const Eigen::MatrixXd& a) {
  const int n = static_cast<int>(a.rows());
  const int m = static_cast<int>(a.cols());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);  // p[j]: row matched to column j
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      U4D_ASSERT(j1 != 0);
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {  // augment along the path
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  return row_to_col;
}

}  // namespace

std::vector<int> MinCostAssignment(const Eigen::MatrixXd& cost) {
  U4D_CHECK(cost.allFinite(), "MinCostAssignment: the cost matrix holds a non-finite value");
  const int rows = static_cast<int>(cost.rows());
  const int cols = static_cast<int>(cost.cols());
  if (rows == 0 || cols == 0) return std::vector<int>(rows, -1);
  if (rows <= cols) return AssignRows(cost);
  // More rows than columns: assign the columns, then invert.
  const Eigen::MatrixXd transposed = cost.transpose();
  const std::vector<int> col_to_row = AssignRows(transposed);
  std::vector<int> row_to_col(rows, -1);
  for (int c = 0; c < cols; ++c)
    if (col_to_row[c] >= 0) row_to_col[col_to_row[c]] = c;
  return row_to_col;
}

std::vector<int> MaxScoreAssignment(const Eigen::MatrixXd& score) {
  return MinCostAssignment(-score);
}

}  // namespace u4d::eval
