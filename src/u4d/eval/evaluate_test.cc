#include "u4d/eval/evaluate.h"

#include <unistd.h>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>

#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d::eval {
namespace {

constexpr int kFrames = 3;

fs::path FreshDir(const std::string& name) { return test_util::FreshTestDir("eval_test", name); }

open3d::geometry::TriangleMesh Square() {
  open3d::geometry::TriangleMesh m;
  const double h = 0.2, z = 2;
  m.vertices_ = {{-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}};
  m.triangles_ = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// Two views, three frames, one static square "person" (id 1) with complete GT
// made by this module's rasteriser, so the GT is exactly self-consistent.
Capture WriteTinyCapture(const fs::path& dir) {
  Capture c;
  c.name = "tiny";
  c.num_frames = kFrames;
  for (int v = 0; v < 2; ++v) {
    CaptureView view;
    view.name = "cam" + std::to_string(v);
    Camera cam;
    cam.width = 40;
    cam.height = 32;
    cam.K << 100, 0, 19.5, 0, 100, 15.5, 0, 0, 1;
    cam.cam_from_world.translation = {0.04 * v, 0, 0};  // 2 px apart
    view.cameras = {cam};
    view.source.path = "images/" + view.name + "/{:06d}.png";
    c.views.push_back(view);
  }
  WriteCapture(c, dir);
  const auto mesh = Square();
  std::vector<Person3d> people(1);
  people[0].id = 1;
  for (int j = 0; j < 17; ++j) people[0].joints.emplace_back(0.01 * j, 1.0 + 0.05 * j, 2);
  for (int f = 0; f < kFrames; ++f) {
    for (const CaptureView& v : c.views) {
      const Rasterization r = RasterizeMeshes({&mesh}, {1}, v.cameras[0]);
      WriteInstanceMask(dir / layout::GtInstances(v.name, f),
                        dir / layout::GtInstancesInfo(v.name, f),
                        InstanceMask{r.labels, {{1, "person", 1.0}}});
      WritePfm(dir / layout::GtDepth(v.name, f), r.depth);
      if (f + 1 < kFrames) {  // the last frame has no flow
        WriteFlo(dir / layout::GtFlow(v.name, f), cv::Mat(32, 40, CV_32FC2, cv::Scalar(0, 0)));
        WriteImage(dir / layout::GtFlowValid(v.name, f), cv::Mat(32, 40, CV_8UC1, cv::Scalar(255)));
      }
    }
    WritePoses3dJson(dir / layout::GtJoints3d(f), people, "h36m17");
    fs::create_directories((dir / layout::GtMesh(1, f)).parent_path());
    EXPECT_TRUE(open3d::io::WriteTriangleMesh((dir / layout::GtMesh(1, f)).string(), mesh));
  }
  return c;
}

TEST(EvaluateCapture, GroundTruthAgainstItselfIsPerfect) {
  const fs::path dir = FreshDir("perfect");
  WriteTinyCapture(dir);
  EvalOptions options;
  options.keyframe_interval = 2;
  const EvalReport r = EvaluateCapture({dir, dir / "gt", false}, options);
  ASSERT_TRUE(r.instances && r.depth && r.depth_people && r.flow && r.poses && r.meshes &&
              r.projection_error && r.silhouette_overlap_error);
  EXPECT_EQ(r.instances->num_images, 2 * kFrames);
  EXPECT_DOUBLE_EQ(r.instances->MeanInstanceIoU(), 1.0);
  EXPECT_DOUBLE_EQ(r.instances->per_class.at("person").IoU(), 1.0);
  EXPECT_EQ(r.instances->missed + r.instances->false_positives + r.instances->merged, 0);
  EXPECT_EQ(r.depth->AbsRel(), 0.0);
  EXPECT_EQ(r.depth->Completeness(), 1.0);
  EXPECT_EQ(r.depth_people->Delta1Pct(), 1.0);
  EXPECT_EQ(r.depth->gt_valid, 2 * kFrames * 400);  // 20 x 20 pixels per image
  EXPECT_EQ(r.flow->Epe(), 0.0);
  EXPECT_EQ(r.flow->gt_valid, 2 * (kFrames - 1) * 40 * 32);
  // People and background split the image's pixels.
  ASSERT_TRUE(r.flow_people && r.flow_background);
  EXPECT_EQ(r.flow_people->gt_valid + r.flow_background->gt_valid, r.flow->gt_valid);
  EXPECT_EQ(r.flow_people->gt_valid, 2 * (kFrames - 1) * 400);
  EXPECT_EQ(r.silhouette_overlap_error->Mean(), 0.0);
  EXPECT_EQ(r.silhouette_overlap_error->count, 2);  // frame 1 in each view (key-frames 0, 2)
  EXPECT_EQ(r.poses->Mpjpe(), 0.0);
  EXPECT_EQ(r.poses->pcp.Rate(), 1.0);
  EXPECT_EQ(r.meshes->matched, kFrames);
  EXPECT_EQ(r.meshes->chamfer.Mean(), 0.0);
  EXPECT_EQ(r.projection_error->Mean(), 0.0);
  EXPECT_EQ(r.projection_error->count, 2 * kFrames);
  EXPECT_TRUE(r.missing_predictions.empty());
  ASSERT_TRUE(r.identity);
  const IdentitySummary id = r.identity->Summarize();
  ASSERT_EQ(id.people.size(), 1u);
  EXPECT_EQ(id.people[0].pred_ids, std::vector<int>{1});
  EXPECT_EQ(id.switches + id.cross_view_disagreements + id.shared_pred_ids, 0);
  ASSERT_TRUE(id.with_meshes);
  EXPECT_EQ(id.visible_frames, kFrames);
  EXPECT_EQ(id.no_mesh_frames, 0);
  const nlohmann::json j = r.ToJson();
  EXPECT_EQ(j["instances"]["mean_instance_iou"].get<double>(), 1.0);
  EXPECT_EQ(j["identity"]["mean_ids_per_person"].get<double>(), 1.0);
  EXPECT_FALSE(r.FormatTable().empty());
  fs::remove_all(dir);
}

TEST(EvaluateCapture, InitialMasksWithADroppedView) {
  const fs::path dir = FreshDir("initial");
  const Capture c = WriteTinyCapture(dir);
  for (int f = 0; f < kFrames; ++f) {  // cam0 has perfect initial masks, cam1 none
    const InstanceMask gt = ReadInstanceMask(dir / layout::GtInstances("cam0", f),
                                             dir / layout::GtInstancesInfo("cam0", f));
    WriteInstanceMask(dir / layout::Mask("cam0", f), dir / layout::MaskInfo("cam0", f), gt);
  }
  const EvalReport r = EvaluateCapture({dir, {}, true});
  ASSERT_TRUE(r.instances);
  EXPECT_FALSE(r.depth);
  EXPECT_DOUBLE_EQ(r.instances->MeanInstanceIoU(), 0.5);
  EXPECT_EQ(r.instances->missed, kFrames);
  EXPECT_EQ(r.missing_predictions.at("instances"), kFrames);
  ASSERT_TRUE(r.identity);  // from the same matches: cam0 only, id 1 throughout
  const IdentitySummary id = r.identity->Summarize();
  EXPECT_DOUBLE_EQ(id.mean_ids_per_person, 1.0);
  EXPECT_EQ(id.people.at(0).matched_view_frames, kFrames);
  EXPECT_EQ(id.switches + id.cross_view_disagreements, 0);
  EXPECT_FALSE(id.with_meshes);
  fs::remove_all(dir);
}

TEST(EvaluateCapture, BadInputsNameTheFile) {
  const fs::path dir = FreshDir("bad");
  WriteTinyCapture(dir);
  // A prediction with a depth map of the wrong size.
  const fs::path pred = dir / "pred";
  const fs::path bad_depth = pred / "depth/cam1/000001.pfm";
  WritePfm(bad_depth, cv::Mat(10, 10, CV_32FC1, cv::Scalar(2.0f)));
  try {
    EvaluateCapture({dir, pred, false});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad_depth.string()), std::string::npos) << e.what();
  }
  // A missing GT file.
  fs::remove(bad_depth);
  const fs::path missing = dir / layout::GtDepth("cam1", 2);
  fs::remove(missing);
  WritePfm(pred / "depth/cam0/000000.pfm", cv::Mat(32, 40, CV_32FC1, cv::Scalar(2.0f)));
  try {
    EvaluateCapture({dir, pred, false});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
  // A missing prediction directory.
  EXPECT_THROW(EvaluateCapture({dir, dir / "nope", false}), Error);
  fs::remove_all(dir.parent_path());
}

}  // namespace
}  // namespace u4d::eval
