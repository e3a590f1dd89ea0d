// People on the floor from the detector boxes of several views, and their
// boxes in every view (init.h, step 4b).
#include <algorithm>
#include <cmath>
#include <set>

#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// A HOG window (64x128) holds a ~96 px person with ~16 px above and below;
// boxes that cut a person lower (legs and torso only) end at the feet. The
// feet are taken 1/16 of the box height above its bottom, between the two.
constexpr double kFootAboveBoxBottom = 1.0 / 16.0;

struct FootRay {
  int view = 0, box = 0;              // box: index over all views' boxes
  Eigen::Vector3d origin, direction;  // world; direction unit length
};

FootRay RayOfFoot(const Camera& camera, int view, int index, const cv::Rect& box) {
  const Eigen::Vector2d foot(box.x + 0.5 * box.width,
                             box.y + box.height * (1.0 - kFootAboveBoxBottom));
  FootRay r;
  r.view = view;
  r.box = index;
  r.origin = camera.Center();
  r.direction = (camera.Unproject(foot, 1.0) - r.origin).normalized();
  return r;
}

// The midpoint of the closest approach of two rays, when both meet it in
// front of their cameras and pass within max_gap of each other.
bool Triangulate(const FootRay& a, const FootRay& b, double max_gap, Eigen::Vector3d* point) {
  const Eigen::Vector3d w = a.origin - b.origin;
  const double ab = a.direction.dot(b.direction);
  const double den = 1.0 - ab * ab;
  if (den < 1e-6) return false;  // parallel rays meet nowhere in particular
  const double da = a.direction.dot(w), db = b.direction.dot(w);
  const double sa = (ab * db - da) / den, sb = (db - ab * da) / den;
  if (sa <= 0 || sb <= 0) return false;
  const Eigen::Vector3d pa = a.origin + sa * a.direction, pb = b.origin + sb * b.direction;
  if ((pa - pb).norm() > max_gap) return false;
  *point = 0.5 * (pa + pb);
  return true;
}

struct FootPoint {
  Eigen::Vector3d position;
  int view_a = 0, view_b = 0;
  int box_a = 0, box_b = 0;
};

// Every pair of boxes of two views whose foot rays meet.
std::vector<FootPoint> FootPoints(const std::vector<Camera>& cameras,
                                  const std::vector<std::vector<PersonBox>>& boxes,
                                  const InitOptions& options) {
  std::vector<FootRay> rays;
  for (size_t v = 0; v < boxes.size(); ++v)
    for (const PersonBox& b : boxes[v])
      rays.push_back(
          RayOfFoot(cameras[v], static_cast<int>(v), static_cast<int>(rays.size()), b.box));
  std::vector<FootPoint> points;
  for (size_t i = 0; i < rays.size(); ++i)
    for (size_t j = i + 1; j < rays.size(); ++j) {
      if (rays[i].view == rays[j].view) continue;
      FootPoint p;
      if (!Triangulate(rays[i], rays[j], options.people.foot_max_gap_m, &p.position)) continue;
      p.view_a = rays[i].view;
      p.view_b = rays[j].view;
      p.box_a = rays[i].box;
      p.box_b = rays[j].box;
      points.push_back(p);
    }
  return points;
}

// Greedy clustering of the meeting points on the floor: the point with the
// most others within a person's radius is a person (their mean); every box
// of those points is then used up, so a box explains one person only (a
// pair of boxes of two different people cannot make a third).
std::vector<FloorPerson> Cluster(const std::vector<FootPoint>& points, double radius) {
  std::vector<bool> box_used;
  for (const FootPoint& p : points)
    box_used.resize(std::max<size_t>(box_used.size(), std::max(p.box_a, p.box_b) + 1), false);
  const auto alive = [&](const FootPoint& p) { return !box_used[p.box_a] && !box_used[p.box_b]; };
  const auto near = [&](const FootPoint& a, const FootPoint& b) {
    return (a.position - b.position).norm() < radius;
  };
  std::vector<FloorPerson> people;
  for (;;) {
    int best = -1, best_count = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!alive(points[i])) continue;
      int count = 0;
      for (const FootPoint& q : points) count += alive(q) && near(points[i], q);
      if (count > best_count) best = static_cast<int>(i), best_count = count;
    }
    if (best < 0) return people;
    FloorPerson person;
    std::set<int> views;
    std::vector<int> boxes;
    for (const FootPoint& q : points) {
      if (!alive(q) || !near(points[best], q)) continue;
      person.foot += q.position / best_count;
      views.insert({q.view_a, q.view_b});
      boxes.insert(boxes.end(), {q.box_a, q.box_b});
    }
    for (const int b : boxes) box_used[b] = true;
    person.num_views = static_cast<int>(views.size());
    people.push_back(person);
  }
}

}  // namespace

std::vector<FloorPerson> PeopleFromBoxes(const std::vector<Camera>& cameras,
                                         const std::vector<std::vector<PersonBox>>& boxes,
                                         const InitOptions& options) {
  options.Check();
  U4D_CHECK(cameras.size() == boxes.size(), "PeopleFromBoxes: {} cameras for {} views of boxes",
            cameras.size(), boxes.size());
  if (cameras.size() < 2) return {};
  const Eigen::Vector3d up = RigUpDirection(cameras);
  const std::vector<FootPoint> points = FootPoints(cameras, boxes, options);
  if (points.empty()) return {};
  // The floor: the median height of the meeting points (most pairs are of
  // one person's feet); points far from it pair different people or false
  // boxes. The others are moved onto the floor.
  std::vector<double> heights;
  for (const FootPoint& p : points) heights.push_back(up.dot(p.position));
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  const double floor = heights[heights.size() / 2];
  std::vector<FootPoint> on_floor;
  for (FootPoint p : points) {
    const double h = up.dot(p.position) - floor;
    if (std::abs(h) > options.people.floor_tolerance_m) continue;
    p.position -= h * up;
    on_floor.push_back(p);
  }
  return Cluster(on_floor, options.people.person_radius_m);
}

std::vector<std::vector<PersonBox>> BoxesOfPeople(const std::vector<Camera>& cameras,
                                                  const std::vector<FloorPerson>& people,
                                                  const InitOptions& options) {
  options.Check();
  const Eigen::Vector3d up = cameras.empty() ? Eigen::Vector3d::UnitY() : RigUpDirection(cameras);
  const Eigen::Vector3d a = up.unitOrthogonal(), b = up.cross(a);
  constexpr int kSides = 16;
  std::vector<std::vector<PersonBox>> out(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    const Camera& c = cameras[v];
    for (const FloorPerson& person : people) {
      if (c.Depth(person.foot) <= 0 || !c.InImage(c.Project(person.foot))) continue;
      std::vector<cv::Point2f> corners;
      bool behind = false;
      for (int k = 0; k < kSides && !behind; ++k) {
        const double angle = 2 * M_PI * k / kSides;
        const Eigen::Vector3d rim = person.foot + options.people.person_radius_m *
                                                      (std::cos(angle) * a + std::sin(angle) * b);
        for (const double h : {0.0, options.people.person_height_m}) {
          const Eigen::Vector3d x = rim + h * up;
          if (c.Depth(x) <= 0) behind = true;
          const Eigen::Vector2d p = c.Project(x);
          corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
        }
      }
      if (behind) continue;
      PersonBox box;
      box.box = cv::boundingRect(corners) & cv::Rect(0, 0, c.width, c.height);
      box.score = person.num_views;
      if (box.box.area() > 0) out[v].push_back(box);
    }
  }
  return out;
}

}  // namespace u4d
