// Objects the detector missed in every view (unlabelled_objects.h), against
// the ground truth of a synthetic capture with props: a detector that knows
// no box (its box instances removed from every mask) still leaves the box to
// be found, from the clean plate, as an object; people's parts the detector
// dropped in some views are not.
#include "u4d/pipeline/unlabelled_objects.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/layout.h"
#include "u4d/pipeline/view_stage.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

struct Found {
  double on_box = 0, on_people = 0, on_background = 0;  // found pixels by GT class
  double box = 0, people = 0;                           // visible GT pixels
  double box_found = 0;                                 // of those, found
  int added = 0;
};

// A view's given mask of frame f without the class `drop` (none when
// empty), as a detector that does not know it gives it; empty without a mask
// file (the pipeline's ReadGivenMasks).
InstanceMask GivenMask(const fs::path& capture, const std::string& view, int f,
                       const std::string& drop) {
  if (!fs::exists(capture / layout::Mask(view, f))) return {};
  InstanceMask mask =
      ReadInstanceMask(capture / layout::Mask(view, f), capture / layout::MaskInfo(view, f));
  for (const InstanceInfo& info : mask.instances)
    if (info.label == drop) mask.ids.setTo(0, mask.ids == info.id);
  return mask;
}

// Frames [first, last] of `capture` (last < 0: num_frames - 2), masks
// without the class `drop` (none when empty), each found pixel scored
// against the GT. With `known`, the median background leaves out the pixels
// the given masks explain (as the pipeline does).
Found FindIn(const fs::path& capture, const std::string& drop, bool known = true, int first = 1,
             int last = -1) {
  const Capture cap = ReadCapture(capture);
  FrameReader reader(cap);
  std::vector<BackgroundModel> backgrounds;
  for (int v = 0; v < cap.NumViews(); ++v) {
    const std::string& name = cap.views[v].name;
    std::function<cv::Mat(int)> explained;
    if (known)
      explained = [&](int f) { return ExplainedPixels(GivenMask(capture, name, f, drop), {}); };
    backgrounds.push_back(ReadViewStage(
                              cap, v, [&](int f) { return reader.Read(v, f); }, {}, {}, explained)
                              .background);
  }
  Found found;
  for (int f = first; f <= (last < 0 ? cap.num_frames - 2 : last); ++f) {
    std::vector<Camera> cams;
    std::vector<cv::Mat> images;
    std::vector<InstanceMask> given(cap.NumViews());
    for (int v = 0; v < cap.NumViews(); ++v) {
      const std::string& name = cap.views[v].name;
      cams.push_back(cap.views[v].CameraAt(f));
      images.push_back(reader.Read(v, f));
      given[v] = GivenMask(capture, name, f, drop);
    }
    const size_t num_given = given.size();
    std::vector<size_t> before(num_given);
    for (size_t v = 0; v < num_given; ++v) before[v] = given[v].instances.size();
    const UnlabelledObjectOptions options;
    found.added += AddUnlabelledObjects(
        UnexplainedForeground(cams, images, backgrounds, {}, given, {}, options), options, &given);
    for (int v = 0; v < cap.NumViews(); ++v) {
      const std::string& name = cap.views[v].name;
      const InstanceMask gt = ReadInstanceMask(capture / layout::GtInstances(name, f),
                                               capture / layout::GtInstancesInfo(name, f));
      cv::Mat ours = cv::Mat::zeros(gt.ids.size(), CV_8U);
      for (size_t i = before[v]; i < given[v].instances.size(); ++i) {
        EXPECT_EQ(given[v].instances[i].label, "object");
        ours.setTo(255, given[v].ids == given[v].instances[i].id);
      }
      cv::Mat people = cv::Mat::zeros(gt.ids.size(), CV_8U), box = people.clone();
      for (const InstanceInfo& info : gt.instances) {
        if (info.label == "box") box.setTo(255, gt.ids == info.id);
        if (info.label == "person") people.setTo(255, gt.ids == info.id);
      }
      found.people += cv::countNonZero(people);
      found.on_box += cv::countNonZero(ours & box);
      found.on_people += cv::countNonZero(ours & people);
      found.on_background += cv::countNonZero(ours & (gt.ids == 0));
      found.box += cv::countNonZero(box);
      found.box_found += cv::countNonZero(ours & box);
    }
  }
  return found;
}

// `clean_plate_frames` 0: the background is the median of the capture's frames.
fs::path CaptureWithProps(int clean_plate_frames) {
  synth::SynthOptions o = synth::SynthPreset("objects");
  o.rig.num_views = 6;
  o.rig.image_width = 320;
  o.rig.image_height = 180;
  o.num_frames = 5;
  o.clean_plate_frames = clean_plate_frames;
  o.write_meshes = false;
  return test_util::RemovedAtExit(synth::WriteCaptureToTempDir("unlabelled", o));
}

TEST(UnlabelledObjects, ADetectorThatKnowsNoBoxLeavesItToBeFound) {
  const fs::path capture = CaptureWithProps(3);
  const Found f = FindIn(capture, "box");
  const double total = f.on_box + f.on_people + f.on_background;
  std::printf(
      "[unlabelled] found %d instances, %.0f px: box %.0f, people %.0f, background %.0f; "
      "the box's visible pixels found: %.0f of %.0f\n",
      f.added, total, f.on_box, f.on_people, f.on_background, f.box_found, f.box);
  ASSERT_GT(total, 0);
  EXPECT_GT(f.on_box / total, 0.8) << "what is found is the box";
  EXPECT_GT(f.box_found / f.box, 0.5) << "most of the box is found";
}

// With the detector's every class, nothing is left to find: the people's
// parts it dropped in one view are explained in the others, and where the
// median of the frames holds a person who has since moved, the ghost is not
// an object. Against the clean plate and against the median.
TEST(UnlabelledObjects, NothingIsFoundWhenTheDetectorKnowsEveryClass) {
  for (const int plate : {3, 0}) {
    const Found f = FindIn(CaptureWithProps(plate), "");
    std::printf(
        "[unlabelled] plate frames %d: found %d instances: box %.0f px, people %.0f px "
        "(of %.0f), background %.0f px\n",
        plate, f.added, f.on_box, f.on_people, f.people, f.on_background);
    EXPECT_LT(f.on_people + f.on_background, 0.01 * f.people) << "plate frames " << plate;
  }
}

// Where a person stood in most of the frames, the median of the frames
// holds the person; in a frame after they left, that ghost differs from
// the image, lies outside every given instance and is seen from every view
// (it is where the person was): without the given masks' help the median
// would make it an object. In this world the walkers' legs stand on the
// same floor for frames 0-3 of 6 and the ghost appears in the last frame.
TEST(UnlabelledObjects, WhereAPersonStoodIsNotAnObjectOnceTheyLeave) {
  synth::SynthOptions o = synth::SynthPreset("handshake");
  o.rig.num_views = 8;
  o.rig.image_width = 480;
  o.rig.image_height = 270;
  o.num_frames = 6;
  o.start_frame = 10;
  o.seed = 7;
  o.write_meshes = false;
  const fs::path capture =
      test_util::RemovedAtExit(synth::WriteCaptureToTempDir("unlabelled_walk", o));
  for (const bool known : {false, true}) {
    const Found f = FindIn(capture, "", known, 5, 5);
    std::printf(
        "[unlabelled] %s: found %d instances: people %.0f px (of %.0f), background %.0f px\n",
        known ? "median without the given instances" : "median of all frames", f.added, f.on_people,
        f.people, f.on_background);
    if (known)
      EXPECT_EQ(f.added, 0);
    else
      EXPECT_GT(f.added, 0) << "the world has the ghost this test is about";
  }
}

TEST(UnlabelledObjects, BadInputIsAnError) {
  UnlabelledObjectOptions o;
  o.min_view_fraction = 0;
  EXPECT_THROW(o.Check(), Error);
  std::vector<InstanceMask> given(2);
  EXPECT_THROW(AddUnlabelledObjects({cv::Mat()}, {}, &given), Error);
  EXPECT_THROW(UnexplainedForeground({Camera{}}, {}, {}, {}, {}, {}, {}), Error);
  // A mask whose size is not its view's.
  std::vector<InstanceMask> one(1);
  one[0].ids = cv::Mat::zeros(4, 4, CV_16U);
  EXPECT_THROW(AddUnlabelledObjects({cv::Mat::zeros(3, 3, CV_8U)}, {}, &one), Error);
  const cv::Mat image = cv::Mat::zeros(3, 3, CV_8UC3);
  test_util::ExpectErrorMentions(
      [&] {
        UnexplainedForeground({Camera{}, Camera{}}, {image, image}, {{}, {}}, {},
                              {one[0], InstanceMask{}}, {}, {});
      },
      {"a mask of 4x4", "an image of 3x3"});
}

}  // namespace
}  // namespace u4d
