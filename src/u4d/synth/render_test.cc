#include "u4d/synth/render.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "u4d/synth/environment.h"
#include "u4d/synth/people.h"
#include "u4d/synth/rig.h"
#include "u4d/synth/texture.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

Material NoiseMaterial(uint32_t seed = 1) {
  Material m;
  m.pattern = Material::Pattern::kNoise;
  m.color_a = {0.9f, 0.8f, 0.7f};
  m.color_b = {0.1f, 0.2f, 0.3f};
  m.scale = 0.2f;
  m.seed = seed;
  return m;
}

// A quad centred at `center` spanned by half-axes u and v (normal u x v).
SceneObject MakeQuad(const Eigen::Vector3f& center, const Eigen::Vector3f& u,
                     const Eigen::Vector3f& v, int instance_id) {
  SceneObject o;
  o.instance_id = instance_id;
  o.label = instance_id > 0 ? "person" : "background";
  const Eigen::Vector3f corners[4] = {center - u - v, center + u - v, center + u + v,
                                      center - u + v};
  for (const Eigen::Vector3f& p : corners) {
    o.mesh.vertices.push_back(p);
    o.mesh.texcoords.push_back(p);
    if (instance_id > 0) o.mesh.vertex_part.push_back(BodyPart::kTorso);
  }
  o.mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  o.mesh.face_material = {0, 0};
  o.materials = {NoiseMaterial(instance_id + 7)};
  return o;
}

SceneObject MakeSphere(const Eigen::Vector3f& center, float radius, int instance_id, int rings = 96,
                       int segments = 192) {
  SceneObject o;
  o.instance_id = instance_id;
  SurfaceMesh& m = o.mesh;
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      const Eigen::Vector3f d(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
      m.vertices.push_back(center + radius * d);
      m.texcoords.push_back(radius * d);
      m.vertex_part.push_back(BodyPart::kHead);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      const int c = a + segments, d = b + segments;
      m.faces.emplace_back(a, b, d);
      m.faces.emplace_back(a, d, c);
    }
  m.face_material.assign(m.faces.size(), 0);
  o.materials = {NoiseMaterial(3)};
  return o;
}

SceneObject Translated(SceneObject o, const Eigen::Vector3f& d) {
  for (Eigen::Vector3f& v : o.mesh.vertices) v += d;
  return o;
}

RenderOptions NoNoise() {
  RenderOptions o;
  o.noise_sigma = 0;
  return o;
}

// A camera at `center` looking at `target`, 640x480, 60 degrees.
Camera LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  return MakeLookAtCamera(center, target, Eigen::Vector3d::UnitY(), 640, 480, 60.0);
}

// Depth along the ray of pixel (x, y) to the plane n . X = n . p0 (camera z).
double RayPlaneDepth(const Camera& cam, double x, double y, const Eigen::Vector3d& p0,
                     const Eigen::Vector3d& n) {
  const Eigen::Vector2d nrm = cam.PixelToNormalized({x, y});
  const Eigen::Vector3d dir_world =
      cam.cam_from_world.rotation.transpose() * Eigen::Vector3d(nrm.x(), nrm.y(), 1.0);
  const Eigen::Vector3d c = cam.Center();
  return n.dot(p0 - c) / n.dot(dir_world);
}

TEST(Render, PlaneDepthIsAnalyticAndUnprojectsOntoPlane) {
  const Eigen::Vector3f center(0.3f, 1.1f, -0.2f);
  const Eigen::Vector3f u = Eigen::Vector3f(1.0f, 0.2f, 0.3f).normalized() * 3.0f;
  const Eigen::Vector3f v = Eigen::Vector3f(-0.1f, 1.0f, 0.4f).normalized() * 3.0f;
  SceneFrame frame;
  frame.statics.push_back(MakeQuad(center, u, v, 0));
  const Camera cam = LookAt({1.0, 1.8, 4.0}, center.cast<double>());
  const RenderedView view = RenderView(cam, frame, NoNoise());
  const Eigen::Vector3d n = u.cast<double>().cross(v.cast<double>()).normalized();
  const Eigen::Vector3d p0 = center.cast<double>();
  int checked = 0;
  double max_rel = 0, max_plane = 0;
  for (int y = 0; y < cam.height; y += 7)
    for (int x = 0; x < cam.width; x += 7) {
      const float d = view.depth.at<float>(y, x);
      if (d == 0) continue;
      ++checked;
      const double truth = RayPlaneDepth(cam, x, y, p0, n);
      max_rel = std::max(max_rel, std::abs(d - truth) / truth);
      const Eigen::Vector3d X = cam.Unproject({double(x), double(y)}, d);
      max_plane = std::max(max_plane, std::abs(n.dot(X - p0)) / truth);
      EXPECT_EQ(view.object.at<uint16_t>(y, x), 1);
      EXPECT_EQ(view.instance.at<uint16_t>(y, x), 0);
    }
  EXPECT_GT(checked, 2000);
  EXPECT_LT(max_rel, 1e-4);
  EXPECT_LT(max_plane, 1e-4);
}

// Area of the image of a sphere (camera-frame centre c, radius r): the conic
// M = K^-T (c c^T - (|c|^2 - r^2) I) K^-1 has area pi |det M| / det(M_2x2)^1.5.
double SphereImageArea(const Camera& cam, const Eigen::Vector3d& c, double r) {
  const Eigen::Matrix3d q =
      c * c.transpose() - (c.squaredNorm() - r * r) * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d kinv = cam.K.inverse();
  const Eigen::Matrix3d m = kinv.transpose() * q * kinv;
  return M_PI * std::abs(m.determinant()) / std::pow(m.topLeftCorner<2, 2>().determinant(), 1.5);
}

TEST(Render, SphereSilhouetteAreaMatchesAnalytic) {
  for (const Eigen::Vector3f& center :
       {Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(0.9f, 1.6f, 0.4f)}) {
    SceneFrame frame;
    frame.people.push_back(MakeSphere(center, 0.5f, 1));
    const Camera cam = LookAt({0.0, 1.0, 4.0}, {0.0, 1.0, 0.0});
    const RenderedView view = RenderView(cam, frame, NoNoise());
    const double area = SphereImageArea(cam, cam.cam_from_world * center.cast<double>(), 0.5);
    const double pixels = cv::countNonZero(view.instance == 1);
    EXPECT_NEAR(pixels / area, 1.0, 0.01) << "centre " << center.transpose();
    ASSERT_EQ(view.visibility.size(), 1u);
    EXPECT_EQ(view.visibility[0].instance_id, 1);
    EXPECT_EQ(view.visibility[0].visible_pixels, view.visibility[0].amodal_pixels);
    EXPECT_EQ(view.visibility[0].visible_pixels, pixels);
    EXPECT_EQ(cv::countNonZero(view.part == static_cast<int>(BodyPart::kHead)), pixels);
  }
}

TEST(Render, OccluderWinsDepthTestAndVisibilityCounts) {
  SceneFrame frame;
  frame.statics.push_back(MakeQuad({0, 1, -1}, {3, 0, 0}, {0, 3, 0}, 0));         // back wall z=-1
  frame.people.push_back(MakeQuad({0, 1, 0.5f}, {0.5f, 0, 0}, {0, 0.5f, 0}, 4));  // in front
  frame.people.push_back(MakeQuad({0.5f, 1, 0}, {0.5f, 0, 0}, {0, 0.5f, 0}, 9));  // half hidden
  const Camera cam = LookAt({0.0, 1.0, 4.0}, {0.0, 1.0, 0.0});
  const RenderedView view = RenderView(cam, frame, NoNoise());
  auto at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = cam.Project(p);
    return cv::Point(int(std::lround(px.x())), int(std::lround(px.y())));
  };
  const cv::Point front = at({0.2, 1.1, 0.5}), side = at({0.8, 1.1, 0}), back = at({-2, 2, -1});
  EXPECT_EQ(view.instance.at<uint16_t>(front), 4);
  EXPECT_EQ(view.part.at<uint8_t>(front), static_cast<int>(BodyPart::kTorso));
  EXPECT_NEAR(view.depth.at<float>(front), 3.5, 1e-4);
  EXPECT_EQ(view.instance.at<uint16_t>(side), 9);
  EXPECT_NEAR(view.depth.at<float>(side), 4.0, 1e-4);
  EXPECT_EQ(view.instance.at<uint16_t>(back), 0);
  EXPECT_EQ(view.object.at<uint16_t>(back), 3);  // 2 people, then statics[0]
  EXPECT_EQ(view.part.at<uint8_t>(back), 0);
  EXPECT_NEAR(view.depth.at<float>(back), 5.0, 1e-4);
  ASSERT_EQ(view.visibility.size(), 2u);
  EXPECT_EQ(view.visibility[0].visible_pixels, view.visibility[0].amodal_pixels);
  // Person 9 occupies x in [0, 1] at z = 0; person 4 hides x in [0, 0.5] of it
  // (seen from x=0 the hidden part at z=0 spans [0, 0.5 * 4 / 3.5]).
  const double hidden = 0.5 * 4.0 / 3.5;
  EXPECT_NEAR(view.visibility[1].VisibleFraction(), 1.0 - hidden, 0.02);
}

TEST(Render, TopLeftFillRuleCoversSharedEdgesOnce) {
  // Screen corners exactly on pixel centres: x, y in [10, 20] -> 10 x 10 pixels.
  Camera cam;
  cam.width = 64;
  cam.height = 48;
  cam.K << 64, 0, 0, 0, 64, 0, 0, 0, 1;
  SceneFrame frame;
  const float lo = 10.0f / 64, hi = 20.0f / 64;
  SceneObject q =
      MakeQuad({(lo + hi) / 2, (lo + hi) / 2, 1}, {(hi - lo) / 2, 0, 0}, {0, (hi - lo) / 2, 0}, 1);
  frame.people.push_back(q);
  const RenderedView view = RenderView(cam, frame, NoNoise());
  EXPECT_EQ(cv::countNonZero(view.object), 100);
  EXPECT_EQ(view.object.at<uint16_t>(10, 10), 1);
  EXPECT_EQ(view.object.at<uint16_t>(19, 19), 1);
  EXPECT_EQ(view.object.at<uint16_t>(20, 15), 0);
  EXPECT_EQ(view.object.at<uint16_t>(15, 20), 0);
  EXPECT_EQ(view.visibility[0].amodal_pixels, 100);
}

TEST(Render, NearPlaneClipsTrianglesCrossingTheCamera) {
  // A floor that extends behind the camera: clipped, and what is in front renders exactly.
  SceneFrame frame;
  frame.statics.push_back(MakeQuad({0, 0, 0}, {0, 0, 20}, {20, 0, 0}, 0));  // y = 0
  const Camera cam = LookAt({0.0, 1.5, 0.0}, {0.0, 0.5, -3.0});
  const RenderedView view = RenderView(cam, frame, NoNoise());
  double max_rel = 0;
  int n = 0;
  for (int y = 0; y < cam.height; y += 5)
    for (int x = 0; x < cam.width; x += 5) {
      const double truth = RayPlaneDepth(cam, x, y, {0, 0, 0}, {0, 1, 0});
      const float d = view.depth.at<float>(y, x);
      if (truth > 0 && truth < 20) {  // rays that hit the floor well inside it
        ++n;
        max_rel = std::max(max_rel, std::abs(d - truth) / truth);
      }
    }
  EXPECT_GT(n, 3000);
  EXPECT_LT(max_rel, 1e-4);
}

TEST(Flow, TranslatingPlaneGivesAnalyticFlowAndOcclusion) {
  SceneFrame f0;
  f0.statics.push_back(MakeQuad({0, 1, -1}, {4, 0, 0}, {0, 3, 0}, 0));
  const Eigen::Vector3f c(0, 1, 0), u(0.6f, 0.1f, 0.2f), v(0.0f, 0.6f, -0.1f);
  f0.people.push_back(MakeQuad(c, u, v, 1));
  const Eigen::Vector3f d(0.13f, -0.05f, 0.21f);
  SceneFrame f1 = f0;
  f1.time = 1.0 / 30;
  f1.people[0] = Translated(f0.people[0], d);
  const Camera cam = LookAt({0.5, 1.3, 4.0}, {0.0, 1.0, 0.0});
  const RenderedView v0 = RenderView(cam, f0, NoNoise()), v1 = RenderView(cam, f1, NoNoise());
  const FlowField flow = ForwardFlow(v0, f0, f1, cam, cam, v1);
  const Eigen::Vector3d n = u.cast<double>().cross(v.cast<double>()).normalized();
  double max_err = 0;
  int checked = 0, valid_person = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      if (v0.instance.at<uint16_t>(y, x) != 1) continue;
      const double z = RayPlaneDepth(cam, x, y, c.cast<double>(), n);
      const Eigen::Vector3d X = cam.Unproject({double(x), double(y)}, z);
      const Eigen::Vector2d truth = cam.Project(X + d.cast<double>()) - Eigen::Vector2d(x, y);
      const cv::Vec2f f = flow.flow.at<cv::Vec2f>(y, x);
      max_err = std::max(max_err, (Eigen::Vector2d(f[0], f[1]) - truth).norm());
      ++checked;
      valid_person += flow.valid.at<uint8_t>(y, x) != 0;
    }
  EXPECT_GT(checked, 10000);
  EXPECT_LT(max_err, 0.01);
  EXPECT_EQ(valid_person, checked);  // the plane is in front of everything
  // Background: a point that the moved plane covers at t+1 is invalid; one far
  // from the plane is valid with zero flow (static camera, static geometry).
  int occluded = 0, wrongly_valid = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      if (v0.object.at<uint16_t>(y, x) != 2 || v1.instance.at<uint16_t>(y, x) != 1) continue;
      ++occluded;
      wrongly_valid += flow.valid.at<uint8_t>(y, x) != 0;
    }
  EXPECT_GT(occluded, 100);
  EXPECT_EQ(wrongly_valid, 0);
  const Eigen::Vector2d far = cam.Project({-2.5, 2.5, -1});
  const cv::Point pf(int(std::lround(far.x())), int(std::lround(far.y())));
  EXPECT_EQ(flow.valid.at<uint8_t>(pf), 255);
  EXPECT_EQ(flow.flow.at<cv::Vec2f>(pf), cv::Vec2f(0, 0));
}

TEST(Flow, RotatingCameraGivesAnalyticReprojection) {
  RigOptions rig;
  rig.num_views = 3;
  rig.image_width = 480;
  rig.image_height = 270;
  rig.angular_speed_deg_per_s = 30;
  EnvironmentOptions env;
  SceneFrame f0;
  f0.statics = MakeEnvironment(env);
  SceneFrame f1 = f0;
  f1.time = 0.1;
  const std::vector<Camera> c0 = RigCameras(rig, 0.0), c1 = RigCameras(rig, 0.1);
  const RenderedView v0 = RenderView(c0[1], f0, NoNoise(), 1);
  const RenderedView v1 = RenderView(c1[1], f1, NoNoise(), 1);
  const FlowField flow = ForwardFlow(v0, f0, f1, c0[1], c1[1], v1);
  double max_err = 0, mean_mag = 0;
  int floor_pixels = 0, valid = 0;
  for (int y = 0; y < c0[1].height; ++y)
    for (int x = 0; x < c0[1].width; ++x) {
      if (v0.object.at<uint16_t>(y, x) != 1) continue;  // statics[0] = floor (no people)
      ++floor_pixels;
      if (!flow.valid.at<uint8_t>(y, x)) continue;
      ++valid;
      const double z = RayPlaneDepth(c0[1], x, y, {0, 0, 0}, {0, 1, 0});
      const Eigen::Vector3d X = c0[1].Unproject({double(x), double(y)}, z);
      const Eigen::Vector2d truth = c1[1].Project(X) - Eigen::Vector2d(x, y);
      const cv::Vec2f f = flow.flow.at<cv::Vec2f>(y, x);
      max_err = std::max(max_err, (Eigen::Vector2d(f[0], f[1]) - truth).norm());
      mean_mag += truth.norm();
    }
  EXPECT_GT(floor_pixels, 20000);
  EXPECT_GT(valid, 0.95 * floor_pixels);
  EXPECT_GT(mean_mag / valid, 5.0);  // the camera really moved
  EXPECT_LT(max_err, 0.01);
}

TEST(Flow, StaticSceneStaticCameraHasZeroFlow) {
  SceneFrame f;
  f.statics = MakeEnvironment({});
  const Camera cam = RigCameras({}, 0.0)[2];
  const RenderedView v = RenderView(cam, f, NoNoise());
  const FlowField flow = ForwardFlow(v, f, f, cam, cam, v);
  EXPECT_EQ(cv::countNonZero(flow.valid), cam.width * cam.height);
  std::vector<cv::Mat> ch;
  cv::split(flow.flow, ch);
  EXPECT_EQ(cv::countNonZero(ch[0]), 0);
  EXPECT_EQ(cv::countNonZero(ch[1]), 0);
}

TEST(Render, ColourIsDeterministicAndTextured) {
  SceneFrame frame;
  frame.statics.push_back(MakeQuad({0, 1, 0}, {2, 0, 0}, {0, 2, 0}, 0));
  const Camera cam = LookAt({0.0, 1.0, 3.0}, {0.0, 1.0, 0.0});
  RenderOptions o;
  o.noise_sigma = 2.0f;
  o.noise_seed = 5;
  const cv::Mat a = RenderView(cam, frame, o).color, b = RenderView(cam, frame, o).color;
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  o.noise_seed = 6;
  EXPECT_GT(cv::norm(a, RenderView(cam, frame, o).color, cv::NORM_L1), 0.0);
  // Every textured pattern has contrast; changing the texture changes the image.
  for (auto pattern : {Material::Pattern::kNoise, Material::Pattern::kStripes,
                       Material::Pattern::kChecker, Material::Pattern::kSpots}) {
    SceneFrame f = frame;
    f.statics[0].materials[0].pattern = pattern;
    f.statics[0].materials[0].scale = 0.3f;
    const cv::Mat img = RenderView(cam, f, NoNoise()).color;
    cv::Mat grey;
    cv::extractChannel(img, grey, 1);
    cv::Scalar mean, stddev;
    cv::meanStdDev(grey, mean, stddev);
    EXPECT_GT(stddev[0], 12.0) << "pattern " << int(pattern);
    f.statics[0].materials[0].seed += 1;
    const cv::Mat other = RenderView(cam, f, NoNoise()).color;
    EXPECT_GT(cv::norm(img, other, cv::NORM_L1) / img.total(), 3.0) << "pattern " << int(pattern);
  }
}

TEST(Texture, BandLimitFadesToTheMean) {
  Material m = NoiseMaterial(2);
  m.scale = 0.05f;
  double sum_sharp = 0, sum2_sharp = 0, sum_blur = 0, sum2_blur = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f p(0.0137f * i, 0.0071f * i, 0.3f);
    const float a = EvaluateMaterial(m, p, 0.0f)[0], b = EvaluateMaterial(m, p, 1.0f)[0];
    sum_sharp += a, sum2_sharp += a * a, sum_blur += b, sum2_blur += b * b;
    EXPECT_GE(a, 0.0f);
    EXPECT_LE(a, 1.0f);
  }
  const double var_sharp = sum2_sharp / n - std::pow(sum_sharp / n, 2);
  const double var_blur = sum2_blur / n - std::pow(sum_blur / n, 2);
  EXPECT_GT(std::sqrt(var_sharp), 0.1);
  EXPECT_LT(std::sqrt(var_blur), 1e-6);  // footprint 20x the period: flat
  m.scale = 0;
  EXPECT_THROW(EvaluateMaterial(m, {0, 0, 0}), Error);
}

TEST(Rig, CamerasLookAtTheLookAtPoint) {
  RigOptions o;
  o.look_at = {0.3, 1.2, -0.4};
  o.bob_amplitude = 0.1;
  o.angular_speed_deg_per_s = 20;
  for (double t : {0.0, 0.7}) {
    const std::vector<Camera> cams = RigCameras(o, t);
    ASSERT_EQ(cams.size(), 8u);
    for (const Camera& c : cams) {
      const Eigen::Vector2d p = c.Project(o.look_at);
      EXPECT_NEAR(p.x(), (o.image_width - 1) / 2.0, 1e-9);
      EXPECT_NEAR(p.y(), (o.image_height - 1) / 2.0, 1e-9);
      const Eigen::Vector3d centre = c.Center();
      EXPECT_NEAR(std::hypot(centre.x() - o.look_at.x(), centre.z() - o.look_at.z()), o.radius,
                  1e-9);
      EXPECT_NEAR(centre.y(), o.height, o.bob_amplitude + 1e-9);
      // Up in the world is up in the image.
      EXPECT_LT(c.Project(o.look_at + Eigen::Vector3d(0, 0.1, 0)).y(), p.y());
    }
  }
  // Static rig: the same cameras at every time.
  const std::vector<Camera> a = RigCameras({}, 0.0), b = RigCameras({}, 3.0);
  EXPECT_EQ((a[3].cam_from_world.translation - b[3].cam_from_world.translation).norm(), 0.0);
  RigOptions bad;
  bad.num_views = 0;
  EXPECT_THROW(RigCameras(bad), Error);
}

TEST(Environment, DefaultRigSeesGeometryEverywhere) {
  for (bool indoor : {true, false}) {
    EnvironmentOptions env;
    env.indoor = indoor;
    SceneFrame frame;
    frame.statics = MakeEnvironment(env);
    for (const SceneObject& o : frame.statics) {
      EXPECT_EQ(o.instance_id, 0);
      EXPECT_EQ(o.label, "background");
    }
    RigOptions rig;
    rig.image_width = 320;
    rig.image_height = 180;
    const std::vector<RenderedView> views = RenderViews(RigCameras(rig), frame, NoNoise());
    for (const RenderedView& v : views) {
      EXPECT_EQ(cv::countNonZero(v.depth > 0), v.depth.rows * v.depth.cols) << indoor;
      EXPECT_EQ(cv::countNonZero(v.instance), 0);
    }
  }
}

TEST(Render, RejectsBadInput) {
  SceneFrame frame;
  frame.statics.push_back(MakeQuad({0, 1, 0}, {1, 0, 0}, {0, 1, 0}, 0));
  frame.statics[0].mesh.faces.push_back({0, 1, 7});
  const Camera cam = LookAt({0.0, 1.0, 3.0}, {0.0, 1.0, 0.0});
  EXPECT_THROW(RenderView(cam, frame), Error);
  frame.statics[0].mesh.faces.pop_back();
  Camera distorted = cam;
  distorted.dist[0] = 0.1;
  EXPECT_THROW(RenderView(distorted, frame), Error);
  RenderOptions o;
  o.near_plane = 0;
  EXPECT_THROW(RenderView(cam, frame, o), Error);
}

}  // namespace
}  // namespace u4d::synth

namespace u4d::synth {
namespace {

// Starting from a cached static layer must give exactly the full render:
// same pixels in every buffer, same visibility.
TEST(StaticLayer, GivesTheSameRenderAsAFullRender) {
  const PeopleScript script = MakeHandshakeScript(100, 25, 3);
  SceneFrame frame;
  PosePeople(script, 60, &frame);
  EnvironmentOptions env;
  env.seed = 11;
  frame.statics = MakeEnvironment(env);
  RigOptions rig;
  rig.num_views = 3;
  rig.image_width = 240;
  rig.image_height = 136;
  const std::vector<Camera> cameras = RigCameras(rig);
  const std::vector<StaticLayer> layers = RenderStaticLayers(cameras, frame.statics);
  const std::vector<RenderedView> full = RenderViews(cameras, frame);
  const std::vector<RenderedView> cached = RenderViews(cameras, frame, {}, &layers);
  for (size_t v = 0; v < cameras.size(); ++v) {
    EXPECT_GT(cv::countNonZero(full[v].instance), 100) << "the people must be in view " << v;
    EXPECT_EQ(cv::norm(full[v].color, cached[v].color, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].depth, cached[v].depth, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].instance, cached[v].instance, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].part, cached[v].part, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].object, cached[v].object, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].face, cached[v].face, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(full[v].barycentric, cached[v].barycentric, cv::NORM_INF), 0.0);
    ASSERT_EQ(full[v].visibility.size(), cached[v].visibility.size());
    for (size_t k = 0; k < full[v].visibility.size(); ++k) {
      EXPECT_EQ(full[v].visibility[k].visible_pixels, cached[v].visibility[k].visible_pixels);
      EXPECT_EQ(full[v].visibility[k].amodal_pixels, cached[v].visibility[k].amodal_pixels);
    }
  }
  // A layer made for another camera is refused.
  EXPECT_THROW(RenderView(cameras[0], frame, {}, 0, &layers[1]), Error);
}

}  // namespace
}  // namespace u4d::synth
