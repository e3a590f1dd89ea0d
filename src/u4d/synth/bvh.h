// BVH motion capture files (Biovision hierarchy): parser and forward
// kinematics.
//
// Supported: one ROOT, nested JOINT and "End Site" blocks with OFFSET and
// CHANNELS (any subset and order of X/Y/Zposition and X/Y/Zrotation), then
// MOTION with "Frames:" and "Frame Time:" followed by frames x channels numbers.
// Rotations are in degrees and compose in the order the channels are listed
// (local = translate(offset + position) * R(c1) * R(c2) * R(c3)), the usual
// BVH convention. Units are whatever the file uses (the shared CMU files are
// scaled to metres, y up).
//
// Errors (missing file, unknown keyword or channel, truncated motion data,
// wrong counts) throw u4d::Error naming the file and, where known, the line.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/rigid3.h"
#include "u4d/util/file.h"

namespace u4d::synth {

enum class BvhChannel : uint8_t {
  kXposition,
  kYposition,
  kZposition,
  kXrotation,
  kYrotation,
  kZrotation
};

struct BvhJoint {
  std::string name;  // End Sites are named "<parent name>_End"
  int parent = -1;   // index into BvhMotion::joints; -1 for the root
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // in the parent's frame
  std::vector<BvhChannel> channels;
  int first_channel = 0;  // column of channels[0] in BvhMotion::values
  bool end_site = false;
};

struct BvhMotion {
  std::string source;            // file name, for messages
  std::vector<BvhJoint> joints;  // parents before children (file order)
  int num_channels = 0;
  int num_frames = 0;
  double frame_time = 0;   // seconds per frame
  Eigen::MatrixXd values;  // num_frames x num_channels, file units / degrees
};

// Reads and parses a .bvh file.
BvhMotion ReadBvh(const fs::path& path);
// Parses BVH text; `source` names it in error messages.
BvhMotion ParseBvh(const std::string& text, const std::string& source);

// Index of the joint called `name`, or -1.
int FindBvhJoint(const BvhMotion& motion, const std::string& name);

// world_from_joint for every joint (End Sites included) at `frame`
// (0 <= frame < num_frames). The joint's origin is its position.
std::vector<Rigid3d> BvhForwardKinematics(const BvhMotion& motion, int frame);

// The same with all channels zero: the skeleton's rest pose.
std::vector<Rigid3d> BvhRestPose(const BvhMotion& motion);

}  // namespace u4d::synth
