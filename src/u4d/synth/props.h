// Props of a synthetic scene: rigid objects the people handle, each a
// SceneObject of its own class with an instance id after the people's
// (issue 27: semantic classes, objects never merged with their holder).
//
//  kCarriedBox    a box hanging below the holder's wrist, its long side
//                 along the way the holder faces, its thin side beside the
//                 thigh; it turns with the holder's hips.
//  kDribbledBall  a ball bounced between the floor and the holder's hand:
//                 under the wrist, its top touching the hand at the top of
//                 each bounce, fastest at the floor; it spins as it moves.
//
// A prop's mesh has the same vertices in the same order at every frame (the
// rule of scene.h); its texcoords are its own rest coordinates, so the
// texture moves with it. Props need a holder with a skeleton (a procedural
// person, people.h): captured performers have no joints to hold anything.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "u4d/synth/scene.h"

namespace u4d::synth {

struct PropOptions {
  enum class Kind : uint8_t { kCarriedBox, kDribbledBall };
  Kind kind = Kind::kCarriedBox;
  std::string label;                       // the class written to the GT; empty = "box" or "ball"
  int holder = 0;                          // index into SceneFrame::joints of the person holding it
  bool left_hand = true;                   // which of the holder's hands
  Eigen::Vector3d size{0.45, 0.32, 0.16};  // box: forward, up, side (m); ball: diameter in x
  double period_s = 0.7;                   // ball: seconds of one bounce
  uint32_t seed = 0;                       // colours and pattern

  std::string Label() const;
  void Check() const;  // throws u4d::Error on a bad size, period or holder
};

// Props by name ("box" or "ball"): the i-th held by person i's left hand,
// with the objects preset's sizes. Throws u4d::Error naming an unknown name.
std::vector<PropOptions> PropsFromNames(const std::vector<std::string>& names);

// The props of `frame` (whose people and joints are posed), with instance
// ids first_id, first_id + 1, ... in `props` order. Throws when a holder has
// no skeleton in the frame.
std::vector<SceneObject> PoseProps(const std::vector<PropOptions>& props, const SceneFrame& frame,
                                   int first_id);

}  // namespace u4d::synth
