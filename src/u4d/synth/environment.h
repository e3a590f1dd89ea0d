// Static synthetic environments: a textured floor and a background, as
// SceneObjects with instance_id 0 and label "background" (synth/scene.h).
//
//  floor    the square |x|, |z| <= floor_size / 2 on y = 0, normal +y, checker
//           tiles of floor_tile metres with fine noise detail.
//  indoor   four walls of a square room of side room_size (centred on the
//           origin, from the floor to wall_height) facing inwards, and a
//           ceiling; noise textures. The floor grows to cover the room.
//  outdoor  a vertical cylinder of radius outdoor_radius (facing inwards, up
//           to outdoor_height) with a top cap, and the floor grown to a square
//           of side 2 * outdoor_radius so the ground reaches the horizon wall.
// With the default rig (rig.h) every pixel sees some geometry.
//
// Texcoords are the world positions (static geometry never moves). Colours
// and pattern seeds are drawn from `seed`, deterministically.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "u4d/synth/scene.h"

namespace u4d::synth {

struct EnvironmentOptions {
  uint32_t seed = 0;             // seeds colours and texture patterns
  bool indoor = true;            // indoor room, else outdoor cylinder
  double floor_size = 12.0;      // side of the floor square (m), indoor is max(floor, room)
  double floor_tile = 0.5;       // checker tile side (m)
  double room_size = 12.0;       // indoor: side of the square room (m)
  double wall_height = 4.0;      // indoor: wall height (m)
  double outdoor_radius = 30.0;  // outdoor: radius of the background cylinder (m)
  double outdoor_height = 15.0;  // outdoor: height of the cylinder (m)
  int cylinder_segments = 64;    // outdoor: facets around the cylinder
  // A keyed stage: floor, walls and ceiling (or cylinder and cap) are all
  // the screen colour key_colour (linear BGR), with a faint noise pattern
  // (+-8%), as a green-screen cyclorama.
  bool keyed = false;
  Eigen::Vector3f key_colour{0.05f, 0.45f, 0.08f};

  void Check() const;  // throws u4d::Error on non-positive sizes
};

// The static objects (floor first, then walls/ceiling or cylinder/cap).
std::vector<SceneObject> MakeEnvironment(const EnvironmentOptions& options);

// Appends the quad a, b, c, d (counter-clockwise seen from the visible side)
// with its own four vertices (flat shading), texcoords equal to the given
// positions, both triangles of material `material`.
void AddQuad(SurfaceMesh& mesh, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
             const Eigen::Vector3f& c, const Eigen::Vector3f& d, uint8_t material);

}  // namespace u4d::synth
