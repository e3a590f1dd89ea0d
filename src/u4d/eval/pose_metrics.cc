#include "u4d/eval/pose_metrics.h"

#include <cmath>
#include <limits>

#include "u4d/eval/hungarian.h"
#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// Mean of the joints of an endpoint; false when one of them is missing.
bool Endpoint(const Person3d& p, const std::vector<int>& joints, Eigen::Vector3d* out) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j : joints) {
    if (!p.Valid(j)) return false;
    sum += p.joints[j];
  }
  *out = sum / static_cast<double>(joints.size());
  return true;
}

}  // namespace

std::vector<Limb> H36m17Limbs() {
  return {{"upper_arm", {11}, {12}}, {"upper_arm", {14}, {15}}, {"lower_arm", {12}, {13}},
          {"lower_arm", {15}, {16}}, {"upper_leg", {4}, {5}},   {"upper_leg", {1}, {2}},
          {"lower_leg", {5}, {6}},   {"lower_leg", {2}, {3}},   {"torso", {0}, {8}},
          {"head", {9}, {10}}};
}

std::vector<Limb> Shelf14Limbs() {
  return {{"upper_arm", {9}, {10}}, {"upper_arm", {8}, {7}}, {"lower_arm", {10}, {11}},
          {"lower_arm", {7}, {6}},  {"upper_leg", {3}, {4}}, {"upper_leg", {2}, {1}},
          {"lower_leg", {4}, {5}},  {"lower_leg", {1}, {0}}, {"torso", {2, 3}, {8, 9}},
          {"head", {12}, {13}}};
}

bool Person3d::Valid(int j) const {
  if (j < 0 || j >= static_cast<int>(joints.size()) || !joints[j].allFinite()) return false;
  if (confidence.empty()) return true;
  return std::isfinite(confidence[j]) && confidence[j] > 0;
}

void PoseOptions::Check() const {
  U4D_CHECK(pcp_alpha > 0, "PoseOptions: pcp_alpha must be positive");
  U4D_CHECK(max_match_distance > 0, "PoseOptions: max_match_distance must be positive");
}

double PoseMetrics::Count::Rate() const {
  return total > 0 ? static_cast<double>(correct) / static_cast<double>(total) : kNaN;
}

void PoseMetrics::Add(const PoseMetrics& o) {
  frames += o.frames;
  gt_people += o.gt_people;
  pred_people += o.pred_people;
  matched += o.matched;
  missed += o.missed;
  false_positives += o.false_positives;
  joints += o.joints;
  sum_joint_error += o.sum_joint_error;
  for (const auto& [k, c] : o.pcp_per_limb) {
    pcp_per_limb[k].correct += c.correct;
    pcp_per_limb[k].total += c.total;
  }
  for (const auto& [k, c] : o.pcp_per_person) {
    pcp_per_person[k].correct += c.correct;
    pcp_per_person[k].total += c.total;
  }
  pcp.correct += o.pcp.correct;
  pcp.total += o.pcp.total;
}

double PoseMetrics::Mpjpe() const {
  return joints > 0 ? sum_joint_error / static_cast<double>(joints) : kNaN;
}

nlohmann::json PoseMetrics::ToJson() const {
  nlohmann::json limbs = nlohmann::json::object(), people = nlohmann::json::object();
  for (const auto& [k, c] : pcp_per_limb) limbs[k] = Num(c.Rate());
  for (const auto& [k, c] : pcp_per_person) people[std::to_string(k)] = Num(c.Rate());
  return {
      {"frames", frames},        {"gt_people", gt_people},  {"pred_people", pred_people},
      {"matched", matched},      {"missed", missed},        {"false_positives", false_positives},
      {"mpjpe_m", Num(Mpjpe())}, {"joints", joints},        {"pcp", Num(pcp.Rate())},
      {"pcp_per_limb", limbs},   {"pcp_per_person", people}};
}

PoseMetrics EvaluatePoses(const std::vector<Person3d>& pred, const std::vector<Person3d>& gt,
                          const std::vector<Limb>& limbs, const PoseOptions& options,
                          const std::string& context) {
  options.Check();
  int num_joints = -1;
  for (const auto* set : {&gt, &pred})
    for (const Person3d& p : *set) {
      if (num_joints < 0) num_joints = static_cast<int>(p.joints.size());
      U4D_CHECK(static_cast<int>(p.joints.size()) == num_joints,
                "{}: person {} has {} joints, another has {}", context, p.id, p.joints.size(),
                num_joints);
      U4D_CHECK(p.confidence.empty() || p.confidence.size() == p.joints.size(),
                "{}: person {} has {} confidences for {} joints", context, p.id,
                p.confidence.size(), p.joints.size());
    }
  if (num_joints >= 0)
    for (const Limb& l : limbs) {
      U4D_CHECK(!l.a.empty() && !l.b.empty(), "{}: limb '{}' has an empty endpoint", context,
                l.name);
      for (const auto* e : {&l.a, &l.b})
        for (int j : *e)
          U4D_CHECK(j >= 0 && j < num_joints, "{}: limb '{}' names joint {} of {}", context, l.name,
                    j, num_joints);
    }

  const int ng = static_cast<int>(gt.size()), np = static_cast<int>(pred.size());
  const double kFar = 1e6;
  Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(ng, np, kFar);
  for (int i = 0; i < ng; ++i)
    for (int k = 0; k < np; ++k) {
      double sum = 0;
      int n = 0;
      for (int j = 0; j < num_joints; ++j)
        if (gt[i].Valid(j) && pred[k].Valid(j)) {
          sum += (gt[i].joints[j] - pred[k].joints[j]).norm();
          ++n;
        }
      if (n > 0) cost(i, k) = std::min(sum / n, kFar);
    }
  std::vector<int> match = MinCostAssignment(cost);
  for (int i = 0; i < ng; ++i)
    if (match[i] >= 0 && cost(i, match[i]) > options.max_match_distance) match[i] = -1;

  PoseMetrics m;
  m.frames = 1;
  m.gt_people = ng;
  m.pred_people = np;
  for (int i = 0; i < ng; ++i) {
    const Person3d& g = gt[i];
    const Person3d* p = match[i] >= 0 ? &pred[match[i]] : nullptr;
    if (p) {
      ++m.matched;
      for (int j = 0; j < num_joints; ++j)
        if (g.Valid(j) && p->Valid(j)) {
          m.sum_joint_error += (g.joints[j] - p->joints[j]).norm();
          ++m.joints;
        }
    } else {
      ++m.missed;
    }
    for (const Limb& l : limbs) {
      Eigen::Vector3d ga, gb, pa, pb;
      if (!Endpoint(g, l.a, &ga) || !Endpoint(g, l.b, &gb)) continue;
      bool correct = false;
      if (p && Endpoint(*p, l.a, &pa) && Endpoint(*p, l.b, &pb))
        correct =
            0.5 * ((pa - ga).norm() + (pb - gb).norm()) <= options.pcp_alpha * (ga - gb).norm();
      for (PoseMetrics::Count* c : {&m.pcp_per_limb[l.name], &m.pcp_per_person[g.id], &m.pcp}) {
        ++c->total;
        if (correct) ++c->correct;
      }
    }
  }
  m.false_positives = np - m.matched;
  return m;
}

std::vector<Person3d> ReadPoses3dJson(const fs::path& path, std::string* skeleton) {
  const std::string ctx = path.string();
  const nlohmann::json j = ReadJsonFile(path);
  const auto format = JsonGet<std::string>(j, "format", ctx);
  U4D_CHECK(format == "u4d-poses3d", "{}: expected format 'u4d-poses3d', found '{}'", ctx, format);
  if (j.contains("units")) {
    const auto units = JsonGet<std::string>(j, "units", ctx);
    U4D_CHECK(units == "metres", "{}: expected units 'metres', found '{}'", ctx, units);
  }
  if (skeleton) *skeleton = j.contains("skeleton") ? JsonGet<std::string>(j, "skeleton", ctx) : "";
  const auto people = JsonGet<nlohmann::json>(j, "people", ctx);
  U4D_CHECK(people.is_array(), "{}: 'people' must be an array", ctx);
  std::vector<Person3d> out;
  for (const nlohmann::json& pj : people) {
    Person3d p;
    p.id = JsonGet<int>(pj, "id", ctx);
    const auto joints = JsonGet<std::vector<std::vector<double>>>(pj, "joints", ctx);
    for (const auto& row : joints) {
      U4D_CHECK(row.size() == 3 || row.size() == 4,
                "{}: person {}: a joint must be [x, y, z] or [x, y, z, c], found {} numbers", ctx,
                p.id, row.size());
      p.joints.emplace_back(row[0], row[1], row[2]);
      p.confidence.push_back(row.size() == 4 ? row[3] : 1.0);
    }
    out.push_back(std::move(p));
  }
  return out;
}

void WritePoses3dJson(const fs::path& path, const std::vector<Person3d>& people,
                      const std::string& skeleton) {
  nlohmann::json arr = nlohmann::json::array();
  for (const Person3d& p : people) {
    nlohmann::json joints = nlohmann::json::array();
    for (size_t j = 0; j < p.joints.size(); ++j)
      joints.push_back({p.joints[j].x(), p.joints[j].y(), p.joints[j].z(),
                        p.confidence.empty() ? 1.0 : p.confidence[j]});
    arr.push_back({{"id", p.id}, {"joints", joints}});
  }
  WriteJsonFileAtomic(
      path,
      {{"format", "u4d-poses3d"}, {"skeleton", skeleton}, {"units", "metres"}, {"people", arr}});
}

}  // namespace u4d::eval
