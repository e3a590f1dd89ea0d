#include "u4d/synth/environment.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "u4d/util/check.h"

namespace u4d::synth {

void AddQuad(SurfaceMesh& mesh, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
             const Eigen::Vector3f& c, const Eigen::Vector3f& d, uint8_t material) {
  const int base = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3f& p : {a, b, c, d}) {
    mesh.vertices.push_back(p);
    mesh.texcoords.push_back(p);
  }
  mesh.faces.emplace_back(base, base + 1, base + 2);
  mesh.faces.emplace_back(base, base + 2, base + 3);
  mesh.face_material.push_back(material);
  mesh.face_material.push_back(material);
}

namespace {

SceneObject Background() {
  SceneObject o;
  o.instance_id = 0;
  o.label = "background";
  return o;
}

Eigen::Vector3f RandomColor(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  return {u(rng), u(rng), u(rng)};
}

}  // namespace

void EnvironmentOptions::Check() const {
  U4D_CHECK(floor_size > 0 && floor_tile > 0 && room_size > 0 && wall_height > 0 &&
                outdoor_radius > 0 && outdoor_height > 0,
            "EnvironmentOptions: sizes must be positive (floor {}, tile {}, room {}, wall {}, "
            "radius {}, height {})",
            floor_size, floor_tile, room_size, wall_height, outdoor_radius, outdoor_height);
  U4D_CHECK(key_colour.minCoeff() >= 0 && key_colour.maxCoeff() <= 1,
            "EnvironmentOptions: key_colour must be linear BGR in [0, 1]");
  U4D_CHECK(cylinder_segments >= 3, "EnvironmentOptions: cylinder_segments must be >= 3, got {}",
            cylinder_segments);
}

std::vector<SceneObject> MakeEnvironment(const EnvironmentOptions& o) {
  o.Check();
  std::mt19937 rng(o.seed * 2654435761u + 12345u);
  std::vector<SceneObject> objects;

  // Floor: normal +y, so counter-clockwise seen from above.
  SceneObject floor = Background();
  const float h = 0.5f * static_cast<float>(o.indoor ? std::max(o.floor_size, o.room_size)
                                                     : 2 * o.outdoor_radius);
  AddQuad(floor.mesh, {-h, 0, -h}, {-h, 0, h}, {h, 0, h}, {h, 0, -h}, 0);
  Material tiles;
  tiles.pattern = Material::Pattern::kChecker;
  tiles.color_a = RandomColor(rng, 0.45f, 0.7f);
  tiles.color_b = RandomColor(rng, 0.1f, 0.3f);
  tiles.scale = static_cast<float>(2 * o.floor_tile);
  tiles.seed = rng();
  floor.materials.push_back(tiles);
  objects.push_back(std::move(floor));

  SceneObject back = Background();
  Material wall;
  wall.pattern = Material::Pattern::kNoise;
  wall.color_a = RandomColor(rng, 0.5f, 0.8f);
  wall.color_b = RandomColor(rng, 0.15f, 0.4f);
  wall.seed = rng();
  if (o.indoor) {
    wall.scale = 0.4f;
    const float r = 0.5f * static_cast<float>(o.room_size), top = static_cast<float>(o.wall_height);
    // Walls facing inwards: counter-clockwise seen from inside the room.
    AddQuad(back.mesh, {-r, 0, -r}, {r, 0, -r}, {r, top, -r}, {-r, top, -r}, 0);    // z = -r
    AddQuad(back.mesh, {r, 0, r}, {-r, 0, r}, {-r, top, r}, {r, top, r}, 0);        // z = +r
    AddQuad(back.mesh, {-r, 0, r}, {-r, 0, -r}, {-r, top, -r}, {-r, top, r}, 0);    // x = -r
    AddQuad(back.mesh, {r, 0, -r}, {r, 0, r}, {r, top, r}, {r, top, -r}, 0);        // x = +r
    AddQuad(back.mesh, {-r, top, -r}, {r, top, -r}, {r, top, r}, {-r, top, r}, 1);  // ceiling
    Material ceiling = wall;
    ceiling.pattern = Material::Pattern::kSpots;
    ceiling.scale = 0.6f;
    ceiling.seed = rng();
    back.materials = {wall, ceiling};
  } else {
    wall.scale = 3.0f;
    const float r = static_cast<float>(o.outdoor_radius),
                top = static_cast<float>(o.outdoor_height);
    const int n = o.cylinder_segments;
    for (int i = 0; i < n; ++i) {
      const float a0 = 2 * static_cast<float>(M_PI) * i / n;
      const float a1 = 2 * static_cast<float>(M_PI) * (i + 1) / n;
      const Eigen::Vector3f p0(r * std::cos(a0), 0, r * std::sin(a0));
      const Eigen::Vector3f p1(r * std::cos(a1), 0, r * std::sin(a1));
      const Eigen::Vector3f up(0, top, 0);
      AddQuad(back.mesh, p0, p1, p1 + up, p0 + up, 0);
      // Cap triangle (fan around the top centre), facing down.
      const int base = static_cast<int>(back.mesh.vertices.size());
      for (const Eigen::Vector3f& p :
           {Eigen::Vector3f(up), Eigen::Vector3f(p0 + up), Eigen::Vector3f(p1 + up)}) {
        back.mesh.vertices.push_back(p);
        back.mesh.texcoords.push_back(p);
      }
      back.mesh.faces.emplace_back(base, base + 1, base + 2);
      back.mesh.face_material.push_back(1);
    }
    Material sky;
    sky.pattern = Material::Pattern::kNoise;
    sky.color_a = {0.95f, 0.85f, 0.75f};
    sky.color_b = {0.8f, 0.6f, 0.45f};
    sky.scale = 8.0f;
    sky.seed = rng();
    back.materials = {wall, sky};
  }
  objects.push_back(std::move(back));
  if (o.keyed) {
    Material screen;
    screen.pattern = Material::Pattern::kNoise;
    screen.color_a = 1.08f * o.key_colour;
    screen.color_b = 0.92f * o.key_colour;
    screen.scale = 0.7f;
    for (SceneObject& object : objects)
      for (Material& m : object.materials) {
        screen.seed = m.seed;
        m = screen;
      }
  }
  return objects;
}

}  // namespace u4d::synth
