// A scene resumes only from the inputs and options it was computed from
// (pipeline.h "Resume", scene_resume.h): after a camera moved in
// calibration.json, a mask changed or an option changed, the rerun says what
// changed and recomputes, and the scene then holds exactly the files that a
// fresh run writes (no mix of the two runs); another capture's scene is left
// alone.
#include <map>

#include <gtest/gtest.h>

#include "u4d/io/capture.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/pipeline/pipeline.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// 3 views at 160x90, 2 frames, with masks and 2D keypoints.
fs::path TinyCapture(const std::string& name) {
  return test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
      "pipeline_resume_" + name, synth::SmallHandshakeOptions(3, 160, 90, 2)));
}

// The bookkeeping is under test, not the quality.
RunOptions TinyOptions() {
  RunOptions o;
  o.joint.rounds = 1;
  o.progress = false;
  o.picture_width = 80;
  o.frame_setup.working_width = 96;
  o.evaluate = false;
  return o;
}

// Every file under `dir` (relative path -> bytes) but run.json, which holds
// the run's times.
std::map<std::string, std::string> SceneFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != layout::SceneRunLog())
      files[e.path().lexically_relative(dir).generic_string()] = ReadTextFile(e.path());
  return files;
}

void ExpectSameFiles(const fs::path& a, const fs::path& b) {
  const auto fa = SceneFiles(a), fb = SceneFiles(b);
  std::vector<std::string> names_a, names_b;
  for (const auto& [name, bytes] : fa) names_a.push_back(name);
  for (const auto& [name, bytes] : fb) names_b.push_back(name);
  ASSERT_EQ(names_a, names_b);
  for (const auto& [name, bytes] : fa) EXPECT_TRUE(bytes == fb.at(name)) << name << " differs";
}

// The rerun with `options` into `scene` says what changed (naming
// `mentions`) and recomputes everything: the scene then equals a fresh run's.
void ExpectRecomputedAsFresh(const fs::path& capture, const fs::path& scene,
                             const RunOptions& options, const std::vector<std::string>& mentions) {
  testing::internal::CaptureStdout();
  const RunResult run = RunPipeline(capture, scene, options);
  const std::string printed = testing::internal::GetCapturedStdout();
  EXPECT_EQ(run.segments_skipped, 0);
  EXPECT_NE(printed.find("recomputing the whole scene"), std::string::npos) << printed;
  for (const std::string& m : mentions) EXPECT_NE(printed.find(m), std::string::npos) << m;
  const fs::path fresh = scene.parent_path() / (scene.filename().string() + "_fresh");
  RunPipeline(capture, fresh, options);  // an empty directory: a fresh run
  ExpectSameFiles(scene, fresh);
}

TEST(PipelineResumeTest, AMovedCameraRecomputesTheScene) {
  const fs::path capture = TinyCapture("camera");
  const fs::path scene = test_util::FreshTestDir("pipeline_resume", "camera");
  RunPipeline(capture, scene, TinyOptions());
  // The same inputs resume (nothing to do).
  EXPECT_EQ(static_cast<size_t>(RunPipeline(capture, scene, TinyOptions()).segments_skipped),
            ReadSceneIndex(scene).segments.size());

  // View 1 moves 20 cm sideways.
  nlohmann::json calib = ReadJsonFile(capture / "calibration.json");
  calib["cameras"][1]["t"][0] = calib["cameras"][1]["t"][0].get<double>() + 0.2;
  WriteJsonFileAtomic(capture / "calibration.json", calib);
  ExpectRecomputedAsFresh(capture, scene, TinyOptions(), {"other inputs", "calibration.json"});
  EXPECT_EQ(ReadJsonFile(scene / layout::SceneCalibration())["cameras"][1]["t"][0],
            calib["cameras"][1]["t"][0]);
}

TEST(PipelineResumeTest, AnEditedMaskRecomputesTheScene) {
  const fs::path capture = TinyCapture("mask");
  const fs::path scene = test_util::FreshTestDir("pipeline_resume", "mask");
  RunPipeline(capture, scene, TinyOptions());
  // Nobody detected in view 1 at frame 1 any more.
  const Capture cap = ReadCapture(capture);
  const Camera& cam = cap.views[1].CameraAt(1);
  WriteInstanceMask(capture / layout::Mask(cap.views[1].name, 1),
                    capture / layout::MaskInfo(cap.views[1].name, 1),
                    {cv::Mat::zeros(cam.height, cam.width, CV_16UC1), {}});
  ExpectRecomputedAsFresh(capture, scene, TinyOptions(),
                          {"other inputs", layout::Mask(cap.views[1].name, 1).generic_string()});
}

TEST(PipelineResumeTest, AnotherOptionRecomputesTheScene) {
  const fs::path capture = TinyCapture("option");
  const fs::path scene = test_util::FreshTestDir("pipeline_resume", "option");
  RunPipeline(capture, scene, TinyOptions());
  RunOptions other = TinyOptions();
  other.keyframes.threshold = 0.3;
  ExpectRecomputedAsFresh(capture, scene, other, {"other options", "/keyframes/threshold"});
}

// A directory holding the run of another capture is not replaced unasked.
TEST(PipelineResumeTest, AnotherCapturesSceneIsRefused) {
  const fs::path first = TinyCapture("first");
  const fs::path second = TinyCapture("second");
  const fs::path scene = test_util::FreshTestDir("pipeline_resume", "another");
  RunPipeline(first, scene, TinyOptions());
  const auto before = SceneFiles(scene);
  test_util::ExpectErrorMentions([&] { RunPipeline(second, scene, TinyOptions()); },
                                 {scene.string(), "another capture", "--no-resume"});
  EXPECT_EQ(SceneFiles(scene), before);  // nothing of the earlier run lost
}

}  // namespace
}  // namespace u4d
