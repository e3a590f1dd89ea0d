#include "u4d/joint/parameters.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// The fields of JointWeights by JSON key, in declaration order.
std::vector<std::pair<std::string, double JointWeights::*>> WeightFields() {
  return {{"depth", &JointWeights::depth},
          {"appearance", &JointWeights::appearance},
          {"semantic", &JointWeights::semantic},
          {"flow", &JointWeights::flow},
          {"smooth", &JointWeights::smooth},
          {"smooth_spatial", &JointWeights::smooth_spatial},
          {"smooth_temporal", &JointWeights::smooth_temporal},
          {"contrast", &JointWeights::contrast},
          {"contrast_colour", &JointWeights::contrast_colour},
          {"contrast_label", &JointWeights::contrast_label},
          {"motion_reg", &JointWeights::motion_reg},
          {"motion_reg_label", &JointWeights::motion_reg_label},
          {"motion_reg_app", &JointWeights::motion_reg_app},
          {"pose", &JointWeights::pose},
          {"pose_2d", &JointWeights::pose_2d},
          {"pose_3d", &JointWeights::pose_3d}};
}

std::vector<std::pair<std::string, bool JointTerms::*>> TermFields() {
  return {{"depth", &JointTerms::depth},           {"appearance", &JointTerms::appearance},
          {"semantic", &JointTerms::semantic},     {"flow", &JointTerms::flow},
          {"smooth", &JointTerms::smooth},         {"contrast", &JointTerms::contrast},
          {"motion_reg", &JointTerms::motion_reg}, {"pose", &JointTerms::pose}};
}

}  // namespace

void JointWeights::Check() const {
  for (const auto& [key, field] : WeightFields()) {
    const double v = this->*field;
    U4D_CHECK(std::isfinite(v) && v >= 0, "joint weight {} must be finite and >= 0, got {}", key,
              v);
  }
}

JointWeights PaperWeights(SceneType scene, int num_views) {
  U4D_CHECK(num_views >= 1, "PaperWeights: num_views must be >= 1, got {}", num_views);
  JointWeights w;  // pairwise constants of the paper: λ_p 0.9, λ_c = λ_s = λ_r = 0.5
  struct Row {
    double d, a, sem, f, s, c, r, p;
  };
  Row row;
  if (scene == SceneType::kOutdoor) {
    row = {1.2, 0.5, 0.5, 0.4, 1.0, 5.0, 0.6, 7.5};
  } else if (num_views < 6) {
    row = {1.0, 0.7, 0.5, 0.6, 0.4, 5.0, 0.4, 7.5};
  } else if (num_views < 20) {
    row = {1.0, 0.7, 0.2, 0.4, 0.4, 5.0, 0.4, 5.0};
  } else {
    row = {1.0, 1.0, 0.5, 0.5, 0.2, 5.0, 0.4, 5.0};
  }
  w.depth = row.d;
  w.appearance = row.a;
  w.semantic = row.sem;
  w.flow = row.f;
  w.smooth_spatial = w.smooth_temporal = row.s;
  w.contrast_colour = w.contrast_label = row.c;
  w.motion_reg_label = w.motion_reg_app = row.r;
  w.pose_2d = w.pose_3d = row.p;
  return w;
}

const std::vector<std::string>& AblationNames() {
  static const std::vector<std::string> names = {"full", "P_M", "P_P", "P_PM", "P_S", "P_PS"};
  return names;
}

JointTerms AblationTerms(const std::string& name) {
  JointTerms t;
  const bool no_motion = name == "P_M" || name == "P_PM";
  const bool no_pose = name == "P_P" || name == "P_PM" || name == "P_PS";
  const bool no_semantic = name == "P_S" || name == "P_PS";
  U4D_CHECK(name == "full" || no_motion || no_pose || no_semantic,
            "unknown ablation '{}' (known: {})", name, fmt::join(AblationNames(), ", "));
  if (no_motion) t.flow = t.motion_reg = false;
  if (no_pose) t.pose = false;
  if (no_semantic) t.semantic = false;
  return t;
}

nlohmann::json ToJson(const JointWeights& weights) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, field] : WeightFields()) j[key] = weights.*field;
  return j;
}

nlohmann::json ToJson(const JointTerms& terms) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, field] : TermFields()) j[key] = terms.*field;
  return j;
}

void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointWeights* weights) {
  U4D_CHECK(j.is_object(), "{}: joint weights must be a JSON object", context);
  const auto fields = WeightFields();
  for (const auto& [key, value] : j.items()) {
    auto it =
        std::find_if(fields.begin(), fields.end(), [&](const auto& f) { return f.first == key; });
    U4D_CHECK(it != fields.end(), "{}: unknown joint weight '{}'", context, key);
    U4D_CHECK(value.is_number(), "{}: joint weight '{}' must be a number", context, key);
    weights->*(it->second) = value.get<double>();
  }
  weights->Check();
}

void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointTerms* terms) {
  U4D_CHECK(j.is_object(), "{}: joint terms must be a JSON object", context);
  const auto fields = TermFields();
  for (const auto& [key, value] : j.items()) {
    auto it =
        std::find_if(fields.begin(), fields.end(), [&](const auto& f) { return f.first == key; });
    U4D_CHECK(it != fields.end(), "{}: unknown joint term '{}'", context, key);
    U4D_CHECK(value.is_boolean(), "{}: joint term '{}' must be true or false", context, key);
    terms->*(it->second) = value.get<bool>();
  }
}

}  // namespace u4d
