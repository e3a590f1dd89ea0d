// Props of the synthetic world against what props.h promises: closed,
// outward-facing rigid meshes that stay with the holder's hand, above the
// floor, and a written capture whose GT and initial masks carry their classes.
#include "u4d/synth/props.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/synth/people.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d::synth {
namespace {

PropOptions Ball() {
  PropOptions o;
  o.kind = PropOptions::Kind::kDribbledBall;
  o.size = {0.24, 0.24, 0.24};
  o.holder = 1;
  return o;
}

// The handshake's people at `frame`, with the box (person 0) and the ball
// (person 1) of the objects preset.
std::vector<SceneObject> PosedProps(const PeopleScript& script, int frame, SceneFrame* out) {
  PosePeople(script, frame, out);
  return PoseProps({PropOptions{}, Ball()}, *out, 3);
}

Eigen::Vector3d Centroid(const SurfaceMesh& m) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& v : m.vertices) c += v.cast<double>();
  return c / static_cast<double>(m.vertices.size());
}

TEST(Props, MeshesAreClosedAndFaceOutwards) {
  const PeopleScript script = MakeHandshakeScript(100, 25, 1);
  SceneFrame frame;
  for (const SceneObject& prop : PosedProps(script, 10, &frame)) {
    const SurfaceMesh& m = prop.mesh;
    ASSERT_EQ(m.vertices.size(), m.texcoords.size());
    ASSERT_EQ(m.faces.size(), m.face_material.size());
    const Eigen::Vector3d centre = Centroid(m);
    double volume = 0;
    for (const Eigen::Vector3i& f : m.faces) {
      const Eigen::Vector3d a = m.vertices[f[0]].cast<double>() - centre;
      const Eigen::Vector3d b = m.vertices[f[1]].cast<double>() - centre;
      const Eigen::Vector3d c = m.vertices[f[2]].cast<double>() - centre;
      const Eigen::Vector3d normal = (b - a).cross(c - a);
      EXPECT_GE(normal.dot(a + b + c), 0) << prop.label << ": a face looks inwards";
      volume += a.dot(b.cross(c)) / 6;
    }
    // The box's volume exactly; the ball's within a faceted sphere's deficit.
    const double expected =
        prop.label == "box" ? 0.45 * 0.32 * 0.16 : 4.0 / 3 * M_PI * std::pow(0.12, 3);
    EXPECT_NEAR(volume, expected, (prop.label == "box" ? 1e-6 : 0.1) * expected) << prop.label;
  }
}

TEST(Props, RigidWithTheHandAndAboveTheFloor) {
  const PeopleScript script = MakeHandshakeScript(100, 25, 2);
  SceneFrame first;
  const std::vector<SceneObject> props0 = PosedProps(script, 0, &first);
  ASSERT_EQ(props0.size(), 2u);
  EXPECT_EQ(props0[0].instance_id, 3);
  EXPECT_EQ(props0[1].instance_id, 4);
  EXPECT_EQ(props0[0].label, "box");
  EXPECT_EQ(props0[1].label, "ball");
  double ball_low = 1e9, ball_high = -1e9;
  for (int f = 1; f < 100; f += 3) {
    SceneFrame frame;
    const std::vector<SceneObject> props = PosedProps(script, f, &frame);
    for (size_t p = 0; p < props.size(); ++p) {
      const SurfaceMesh& a = props0[p].mesh;
      const SurfaceMesh& b = props[p].mesh;
      ASSERT_EQ(a.vertices.size(), b.vertices.size());
      // Rigid: distances between vertices are kept.
      for (size_t i = 0; i + 7 < a.vertices.size(); i += 7)
        EXPECT_NEAR((a.vertices[i] - a.vertices[i + 7]).norm(),
                    (b.vertices[i] - b.vertices[i + 7]).norm(), 1e-4);
      double low = 1e9, high = -1e9;
      for (const auto& v : b.vertices) {
        low = std::min<double>(low, v.y());
        high = std::max<double>(high, v.y());
      }
      EXPECT_GT(low, -1e-4) << props[p].label << " below the floor at frame " << f;
      const Eigen::Vector3d wrist = frame.joints[p == 0 ? 0 : 1][kLeftWrist];
      EXPECT_LT(high, wrist.y()) << props[p].label << " above the hand at frame " << f;
      const Eigen::Vector3d c = Centroid(b);
      EXPECT_LT(Eigen::Vector2d(c.x() - wrist.x(), c.z() - wrist.z()).norm(), 0.2)
          << props[p].label << " away from the hand at frame " << f;
      if (p == 1) {
        ball_low = std::min(ball_low, low);
        ball_high = std::max(ball_high, high);
      }
    }
  }
  // The ball bounces from the floor to the hand.
  EXPECT_LT(ball_low, 0.03);
  EXPECT_GT(ball_high, 0.5);
}

TEST(Props, HoldersNeedASkeleton) {
  SceneFrame frame;
  PosePeople(MakeHandshakeScript(100, 25, 1), 0, &frame);
  PropOptions o;
  o.holder = 2;  // the handshake has two people
  EXPECT_THROW(PoseProps({o}, frame, 3), Error);
  o.holder = 0;
  o.size.y() = 0;
  EXPECT_THROW(o.Check(), Error);
  o = Ball();
  o.period_s = std::nan("");
  EXPECT_THROW(o.Check(), Error);
  o = Ball();
  o.label = "person";
  EXPECT_THROW(o.Check(), Error);
  EXPECT_THROW(PropsFromNames({"box", "chair"}), Error);
  const std::vector<PropOptions> named = PropsFromNames({"ball", "box"});
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0].Label(), "ball");
  EXPECT_EQ(named[1].Label(), "box");
  EXPECT_EQ(named[1].holder, 1);
}

// The objects preset, small: the GT of every view-frame names the classes of
// the objects it shows, and the initial masks carry classes other than person.
TEST(Props, ObjectsPresetWritesClasses) {
  SynthOptions o = SynthPreset("objects");
  o.rig.num_views = 3;
  o.rig.image_width = 240;
  o.rig.image_height = 136;
  o.num_frames = 3;
  o.write_meshes = true;
  SynthSummary summary;
  const fs::path dir = test_util::RemovedAtExit(WriteCaptureToTempDir("props_test", o, &summary));
  EXPECT_EQ(summary.num_people, 2);
  EXPECT_EQ(summary.num_objects, 2);
  std::set<std::string> gt_classes, mask_classes;
  for (const std::string view : {"cam00", "cam01", "cam02"})
    for (int f = 0; f < 3; ++f) {
      for (const InstanceInfo& i : ReadInstanceMask(dir / layout::GtInstances(view, f),
                                                    dir / layout::GtInstancesInfo(view, f))
                                       .instances)
        gt_classes.insert(i.label);
      if (!fs::exists(dir / layout::MaskInfo(view, f))) continue;
      for (const InstanceInfo& i :
           ReadInstanceMask(dir / layout::Mask(view, f), dir / layout::MaskInfo(view, f)).instances)
        mask_classes.insert(i.label);
    }
  EXPECT_EQ(gt_classes, (std::set<std::string>{"ball", "box", "person"}));
  EXPECT_EQ(mask_classes.count("person"), 1u);
  EXPECT_GE(mask_classes.size(), 2u);
  EXPECT_TRUE(fs::exists(dir / layout::GtMesh(4, 2)));  // the ball's GT mesh
}

}  // namespace
}  // namespace u4d::synth
