// 3D human-pose metrics: MPJPE and PCP (as reported on Shelf / Campus).
//
// People are matched one-to-one between prediction and GT per frame by the
// Hungarian method on the mean distance over joints valid in both; a pair
// farther apart than `max_match_distance` is left unmatched.
//   MPJPE  mean Euclidean distance (metres) over all (matched pair, joint
//          valid in both) of the frame; pooled over frames joint-weighted.
//          Unmatched GT people do not enter MPJPE; they are counted as missed.
//   PCP    for every GT person and every limb whose GT endpoints are valid:
//          the limb is correct when the person is matched, both predicted
//          endpoints are valid and
//            (||p_a - g_a|| + ||p_b - g_b||) / 2 <= alpha * ||g_a - g_b||
//          (the "average" PCP variant used by the multi-view literature,
//          alpha = 0.5). A missed person's limbs are all incorrect. PCP is
//          reported per limb name (left and right pooled), per GT person id,
//          and overall = correct limbs / evaluated limbs (limb-weighted).
// A limb endpoint is the mean of one or more joints, so derived endpoints
// (Shelf's torso: mid-hip to mid-shoulder) are expressible.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "u4d/util/file.h"

namespace u4d::eval {

struct Limb {
  std::string name;    // e.g. "upper_arm"; limbs sharing a name are pooled
  std::vector<int> a;  // endpoint a = mean of these joints
  std::vector<int> b;
};

// The internal 17-joint Human3.6M skeleton (docs/conventions.md): upper arms,
// lower arms, upper legs, lower legs (left and right), torso = pelvis-thorax,
// head = neck-head.
std::vector<Limb> H36m17Limbs();
// Shelf / Campus 14-joint GT order (r ankle, r knee, r hip, l hip, l knee,
// l ankle, r wrist, r elbow, r shoulder, l shoulder, l elbow, l wrist,
// bottom head, top head): arms and legs as above, torso = mid-hip to
// mid-shoulder, head = bottom head to top head.
std::vector<Limb> Shelf14Limbs();

struct Person3d {
  int id = 0;
  std::vector<Eigen::Vector3d> joints;  // world, metres
  std::vector<double> confidence;       // per joint; <= 0 or non-finite = missing
  bool Valid(int j) const;
};

struct PoseOptions {
  double pcp_alpha = 0.5;           // PCP threshold as a fraction of GT limb length
  double max_match_distance = 0.5;  // metres, mean joint distance for a match
  void Check() const;
};

struct PoseMetrics {
  int frames = 0;
  int gt_people = 0, pred_people = 0, matched = 0, missed = 0, false_positives = 0;
  int64_t joints = 0;  // joint pairs in MPJPE
  double sum_joint_error = 0;
  struct Count {
    int64_t correct = 0, total = 0;
    double Rate() const;
  };
  std::map<std::string, Count> pcp_per_limb;
  std::map<int, Count> pcp_per_person;  // by GT id
  Count pcp;                            // all limbs

  void Add(const PoseMetrics& o);
  double Mpjpe() const;  // metres; NaN when no joint was compared
  nlohmann::json ToJson() const;
};

// One frame. Throws u4d::Error naming `context` when a person's joint count
// differs from the others' or a limb names a joint out of range.
PoseMetrics EvaluatePoses(const std::vector<Person3d>& pred, const std::vector<Person3d>& gt,
                          const std::vector<Limb>& limbs, const PoseOptions& options,
                          const std::string& context);

// Reads {"format":"u4d-poses3d","skeleton":..,"units":"metres",
// "people":[{"id":..,"joints":[[x,y,z,c],...]}]}. (A local reader until the
// general one in io/poses.h exists.) Throws naming the file on any problem.
std::vector<Person3d> ReadPoses3dJson(const fs::path& path, std::string* skeleton = nullptr);
void WritePoses3dJson(const fs::path& path, const std::vector<Person3d>& people,
                      const std::string& skeleton);

}  // namespace u4d::eval
