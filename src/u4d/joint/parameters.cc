#include "u4d/joint/parameters.h"

#include <cmath>

#include <fmt/format.h>

#include "u4d/joint/joint_options.h"
#include "u4d/util/check.h"

namespace u4d {

void JointWeights::Check() const {
  JointWeights copy = *this;
  for (const OptionEntry& e : OptionsOf(&copy).Entries()) {
    const double v = e.get().get<double>();
    U4D_CHECK(std::isfinite(v) && v >= 0, "joint weight {} must be finite and >= 0, got {}", e.key,
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
  JointWeights copy = weights;
  return OptionsToJson(OptionsOf(&copy));
}

nlohmann::json ToJson(const JointTerms& terms) {
  JointTerms copy = terms;
  return OptionsToJson(OptionsOf(&copy));
}

void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointWeights* weights) {
  UpdateOptionsFromJson(OptionsOf(weights), j, context + ": joint weights");
  weights->Check();
}

void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointTerms* terms) {
  UpdateOptionsFromJson(OptionsOf(terms), j, context + ": joint terms");
}

}  // namespace u4d
