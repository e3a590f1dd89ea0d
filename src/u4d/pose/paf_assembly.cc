#include "u4d/pose/paf_assembly.h"

#include <algorithm>
#include <cmath>

#include "u4d/util/check.h"

namespace u4d {

void PafAssemblyOptions::Check() const {
  U4D_CHECK(min_joint_score >= 0, "PafAssemblyOptions.min_joint_score must be >= 0, got {}",
            min_joint_score);
  U4D_CHECK(min_paf_score >= 0, "PafAssemblyOptions.min_paf_score must be >= 0, got {}",
            min_paf_score);
  U4D_CHECK(min_joints >= 1 && min_joints <= 25,
            "PafAssemblyOptions.min_joints must be in [1, 25], got {}", min_joints);
  U4D_CHECK(min_mean_score >= 0, "PafAssemblyOptions.min_mean_score must be >= 0, got {}",
            min_mean_score);
}

const std::array<std::array<int, 2>, 26>& Body25Limbs() {
  static const std::array<std::array<int, 2>, 26> kLimbs = {{
      {1, 8},   {9, 10},  {10, 11}, {8, 9},   {8, 12},  {12, 13}, {13, 14}, {1, 2},   {2, 3},
      {3, 4},   {2, 17},  {1, 5},   {5, 6},   {6, 7},   {5, 18},  {1, 0},   {0, 15},  {0, 16},
      {15, 17}, {16, 18}, {14, 19}, {19, 20}, {14, 21}, {11, 22}, {22, 23}, {11, 24},
  }};
  return kLimbs;
}

namespace {

struct Person {
  std::array<int, 25> cand;  // candidate index per joint type, -1 = none
  double score = 0;
  int count = 0;
  Person() { cand.fill(-1); }
};

}  // namespace

std::vector<Pose2d> AssembleBody25(const FourdaDetectionFrame& frame, int width, int height,
                                   const PafAssemblyOptions& options) {
  options.Check();
  U4D_CHECK(width > 0 && height > 0, "AssembleBody25: image size must be positive, got {}x{}",
            width, height);
  U4D_CHECK(frame.joints.size() == 25 && frame.pafs.size() == 26,
            "AssembleBody25: expected 25 joint types and 26 limbs, got {} and {}",
            frame.joints.size(), frame.pafs.size());
  const auto& limbs = Body25Limbs();
  std::vector<Person> people;
  // owner[type][candidate] = person index or -1.
  std::vector<std::vector<int>> owner(25);
  for (int t = 0; t < 25; ++t) owner[t].assign(frame.joints[t].cols(), -1);

  for (int l = 0; l < 26; ++l) {
    const int ta = limbs[l][0], tb = limbs[l][1];
    const Eigen::Matrix3Xd& ja = frame.joints[ta];
    const Eigen::Matrix3Xd& jb = frame.joints[tb];
    const Eigen::MatrixXd& paf = frame.pafs[l];
    U4D_CHECK(paf.rows() == ja.cols() && paf.cols() == jb.cols(),
              "AssembleBody25: limb {} has a {}x{} score matrix for {} and {} candidates", l,
              paf.rows(), paf.cols(), ja.cols(), jb.cols());
    struct Conn {
      double s;
      int a, b;
    };
    std::vector<Conn> conns;
    for (int a = 0; a < paf.rows(); ++a) {
      if (ja(2, a) < options.min_joint_score) continue;
      for (int b = 0; b < paf.cols(); ++b) {
        if (jb(2, b) < options.min_joint_score || !(paf(a, b) >= options.min_paf_score)) continue;
        conns.push_back({paf(a, b), a, b});
      }
    }
    std::sort(conns.begin(), conns.end(), [](const Conn& x, const Conn& y) { return x.s > y.s; });
    std::vector<bool> used_a(paf.rows(), false), used_b(paf.cols(), false);
    for (const Conn& c : conns) {
      if (used_a[c.a] || used_b[c.b]) continue;
      used_a[c.a] = used_b[c.b] = true;
      const int pa = owner[ta][c.a], pb = owner[tb][c.b];
      if (pa >= 0 && pb >= 0) {
        if (pa == pb) {
          people[pa].score += c.s;
          continue;
        }
        bool disjoint = true;
        for (int t = 0; t < 25; ++t) disjoint &= people[pa].cand[t] < 0 || people[pb].cand[t] < 0;
        if (!disjoint) continue;
        for (int t = 0; t < 25; ++t) {
          if (people[pb].cand[t] < 0) continue;
          people[pa].cand[t] = people[pb].cand[t];
          owner[t][people[pb].cand[t]] = pa;
        }
        people[pa].score += people[pb].score + c.s;
        people[pa].count += people[pb].count;
        people[pb] = Person();
        people[pb].count = 0;
      } else if (pa >= 0 || pb >= 0) {
        const int p = pa >= 0 ? pa : pb;
        const int t = pa >= 0 ? tb : ta;
        const int cand = pa >= 0 ? c.b : c.a;
        if (people[p].cand[t] >= 0) continue;  // that joint type is taken
        people[p].cand[t] = cand;
        owner[t][cand] = p;
        people[p].score += c.s + (pa >= 0 ? jb(2, c.b) : ja(2, c.a));
        people[p].count += 1;
      } else {
        Person p;
        p.cand[ta] = c.a;
        p.cand[tb] = c.b;
        p.score = c.s + ja(2, c.a) + jb(2, c.b);
        p.count = 2;
        owner[ta][c.a] = owner[tb][c.b] = static_cast<int>(people.size());
        people.push_back(p);
      }
    }
  }

  const std::array<int, 17>& map = Coco17FromBody25();
  std::vector<Pose2d> out;
  for (const Person& p : people) {
    if (p.count < options.min_joints || p.score / p.count < options.min_mean_score) continue;
    Pose2d pose;
    double conf_sum = 0;
    int n = 0;
    for (int k = 0; k < 17; ++k) {
      const int t = map[k];
      const int c = p.cand[t];
      if (c < 0) continue;
      const Eigen::Vector3d& j = frame.joints[t].col(c);
      const double conf = std::clamp(j(2), 0.0, 1.0);
      if (conf <= 0) continue;
      pose.keypoints[k] = Eigen::Vector3d(j(0) * width, j(1) * height, conf);
      conf_sum += conf;
      ++n;
    }
    if (n == 0) continue;
    pose.score = conf_sum / n;
    out.push_back(pose);
  }
  return out;
}

}  // namespace u4d
