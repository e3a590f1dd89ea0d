#include "u4d/joint/motion_labels.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "u4d/util/check.h"

namespace u4d {

void MotionLabelOptions::Check() const {
  U4D_CHECK(window >= 0 && window <= 64, "MotionLabelOptions.window must be in [0, 64], got {}",
            window);
  U4D_CHECK(std::isfinite(cluster_radius) && cluster_radius >= 0,
            "MotionLabelOptions.cluster_radius must be finite and >= 0, got {}", cluster_radius);
  U4D_CHECK(max_centres >= 0, "MotionLabelOptions.max_centres must be >= 0, got {}", max_centres);
  U4D_CHECK(std::isfinite(support_radius) && support_radius > 0,
            "MotionLabelOptions.support_radius must be finite and > 0, got {}", support_radius);
}

std::vector<Eigen::Vector2f> BuildMotionLabels(const std::vector<SparseMotion>& sparse,
                                               const MotionLabelOptions& options) {
  options.Check();
  // Greedy clustering in input order: a displacement joins the first cluster
  // whose running mean is within cluster_radius, else starts a new one.
  struct Cluster {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int count = 0;
    Eigen::Vector2d Mean() const { return sum / count; }
  };
  std::vector<Cluster> clusters;
  for (size_t i = 0; i < sparse.size(); ++i) {
    const Eigen::Vector2d& d = sparse[i].displacement;
    U4D_CHECK(d.allFinite() && sparse[i].pixel.allFinite(),
              "BuildMotionLabels: sparse correspondence {} is not finite (pixel ({}, {}), "
              "displacement ({}, {}))",
              i, sparse[i].pixel.x(), sparse[i].pixel.y(), d.x(), d.y());
    bool joined = false;
    for (Cluster& c : clusters) {
      if ((c.Mean() - d).norm() <= options.cluster_radius) {
        c.sum += d;
        ++c.count;
        joined = true;
        break;
      }
    }
    if (!joined) clusters.push_back({d, 1});
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Cluster& a, const Cluster& b) { return a.count > b.count; });
  if (static_cast<int>(clusters.size()) > options.max_centres) clusters.resize(options.max_centres);

  std::vector<std::pair<long, long>> centres = {{0, 0}};
  for (const Cluster& c : clusters) {
    const Eigen::Vector2d m = c.Mean();
    centres.push_back({std::lround(m.x()), std::lround(m.y())});
  }
  std::set<std::pair<long, long>> labels;  // (dy, dx): sorted by row, then column
  const int w = options.window;
  for (const auto& [cx, cy] : centres)
    for (int dy = -w; dy <= w; ++dy)
      for (int dx = -w; dx <= w; ++dx) labels.insert({cy + dy, cx + dx});
  std::vector<Eigen::Vector2f> out;
  out.reserve(labels.size());
  for (const auto& [dy, dx] : labels)
    out.emplace_back(static_cast<float>(dx), static_cast<float>(dy));
  return out;
}

std::vector<SparseMotion> SparseMotionsFromTracks(const std::vector<TemporalTrack>& tracks,
                                                  int view, int frame_t, double scale) {
  U4D_CHECK(std::isfinite(scale) && scale > 0,
            "SparseMotionsFromTracks: scale must be finite and > 0, got {}", scale);
  std::vector<SparseMotion> out;
  for (const TemporalTrack& t : tracks) {
    if (t.view != view) continue;
    const Eigen::Vector2d* a = t.At(frame_t);
    const Eigen::Vector2d* b = t.At(frame_t + 1);
    if (a == nullptr || b == nullptr) continue;
    SparseMotion s;
    s.pixel = scale * (a->array() + 0.5) - 0.5;
    s.displacement = scale * (*b - *a);
    s.instance = t.instance;
    out.push_back(s);
  }
  return out;
}

MotionLabelGrid::MotionLabelGrid(const std::vector<Eigen::Vector2f>& motions) {
  const auto integer = [](const Eigen::Vector2f& m) {
    return m.x() == std::round(m.x()) && m.y() == std::round(m.y());
  };
  int x1 = 0, y1 = 0;
  bool first = true;
  for (const Eigen::Vector2f& m : motions) {
    if (!integer(m)) continue;
    const int x = static_cast<int>(m.x()), y = static_cast<int>(m.y());
    if (first) x0 = x1 = x, y0 = y1 = y, first = false;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  if (first) return;
  w = x1 - x0 + 1;
  h = y1 - y0 + 1;
  index.assign(static_cast<size_t>(w) * h, -1);
  for (size_t l = 0; l < motions.size(); ++l) {
    const Eigen::Vector2f& m = motions[l];
    if (integer(m))
      index[(static_cast<int>(m.y()) - y0) * w + static_cast<int>(m.x()) - x0] =
          static_cast<int>(l);
  }
}

int MotionLabelGrid::Find(float fx, float fy) const {
  if (fx != std::round(fx) || fy != std::round(fy)) return -1;
  const int x = static_cast<int>(fx) - x0, y = static_cast<int>(fy) - y0;
  if (x < 0 || y < 0 || x >= w || y >= h) return -1;
  return index[y * w + x];
}

int MotionLabelGrid::Nearest(const Eigen::Vector2f& m) const {
  if (!(std::abs(m.x()) < 1e6f && std::abs(m.y()) < 1e6f)) return -1;
  return Find(static_cast<float>(std::lround(m.x())), static_cast<float>(std::lround(m.y())));
}

}  // namespace u4d
