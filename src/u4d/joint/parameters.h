// The weights and switches of the joint energy (paper Eq. 1):
//
//   E(l,d,m) = λ_d E_d(d) + λ_a E_a(l) + λ_sem E_sem(l) + λ_f E_f(m)
//            + λ_s E_s(l,d) + λ_c E_c(l) + λ_r E_r(l,m) + λ_p E_p(l,d,m)
//
// Defaults are the paper's parameter table (Table "Parameters for all
// datasets"): one row for outdoor scenes and three indoor rows chosen by the
// number of views; λ_p = 0.9 and λ_c = λ_s = λ_r = 0.5 for all. A column of
// the table headed "a/b" holds a single value, read here as a = b.
//
// Each term is normalised to about [0, 1] per pixel (per neighbour pair for
// pairwise terms) before it is weighted; the normalisations are documented
// with each term (docs/joint.md).
//
// Ablations (paper Sec. "Ablation study"): P_M drops the motion terms (E_f,
// E_r), P_P the pose term (E_p), P_PM both, P_S the semantic term (E_sem),
// P_PS pose and semantic. Any term can also be switched off alone. In `u4d
// run` the ablation is a preset of the option joint.terms (RunOptions).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/io/capture.h"

namespace u4d {

struct JointWeights {
  double depth = 1.0;             // λ_d
  double appearance = 0.7;        // λ_a
  double semantic = 0.2;          // λ_sem
  double flow = 0.4;              // λ_f
  double smooth = 0.5;            // λ_s
  double smooth_spatial = 0.4;    // λ_s^s
  double smooth_temporal = 0.4;   // λ_s^t
  double contrast = 0.5;          // λ_c
  double contrast_colour = 5.0;   // λ_ca
  double contrast_label = 5.0;    // λ_cl
  double motion_reg = 0.5;        // λ_r
  double motion_reg_label = 0.4;  // λ_r^L (semantic regularisation)
  double motion_reg_app = 0.4;    // λ_r^A (appearance regularisation; the table's λ_r^C)
  double pose = 0.9;              // λ_p
  double pose_2d = 5.0;           // λ_2d
  double pose_3d = 5.0;           // λ_3d

  void Check() const;  // throws u4d::Error naming a negative or non-finite weight
};

// The paper's table row for a scene type and number of views (>= 1).
JointWeights PaperWeights(SceneType scene, int num_views);

// Which terms are on. All on is the full method.
struct JointTerms {
  bool depth = true;       // E_d
  bool appearance = true;  // E_a
  bool semantic = true;    // E_sem
  bool flow = true;        // E_f
  bool smooth = true;      // E_s
  bool contrast = true;    // E_c
  bool motion_reg = true;  // E_r
  bool pose = true;        // E_p

  bool operator==(const JointTerms&) const = default;
};

// "full", "P_M", "P_P", "P_PM", "P_S", "P_PS"; throws on an unknown name,
// listing the known ones.
JointTerms AblationTerms(const std::string& name);
const std::vector<std::string>& AblationNames();

nlohmann::json ToJson(const JointWeights& weights);
nlohmann::json ToJson(const JointTerms& terms);
// Overrides the fields present in `j` (same keys as ToJson); unknown keys and
// non-numeric / non-boolean values throw, naming `context` and the key.
void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointWeights* weights);
void UpdateFromJson(const nlohmann::json& j, const std::string& context, JointTerms* terms);

}  // namespace u4d
