#include "u4d/pipeline/initial_objects.h"

#include <map>

#include <gtest/gtest.h>

#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

TEST(KeepGivenPixelsTest, DroppedPixelsOfANamedInstanceComeBackWithItsId) {
  // Instance 3 (rows 0-3) was named 7 except for row 3 (a hand the hull
  // missed) and one pixel named 8 (split off); instance 5 (rows 6-7) was
  // named nowhere (a false positive); background stays background.
  cv::Mat given = cv::Mat::zeros(8, 6, CV_16UC1), named = given.clone();
  given.rowRange(0, 4).setTo(3);
  given.rowRange(6, 8).setTo(5);
  named.rowRange(0, 3).setTo(7);
  named.at<uint16_t>(0, 0) = 8;
  const cv::Mat kept = KeepGivenPixels(given, named);
  for (int x = 0; x < 6; ++x) {
    EXPECT_EQ(kept.at<uint16_t>(3, x), 7) << x;  // restored with the majority id
    EXPECT_EQ(kept.at<uint16_t>(4, x), 0) << x;  // background
    EXPECT_EQ(kept.at<uint16_t>(6, x), 0) << x;  // the false positive stays dropped
  }
  EXPECT_EQ(kept.at<uint16_t>(0, 0), 8);  // named pixels keep their names
  EXPECT_EQ(kept.at<uint16_t>(1, 1), 7);
}

TEST(KeepGivenPixelsTest, MismatchedMasksAreRefused) {
  const cv::Mat a = cv::Mat::zeros(4, 4, CV_16UC1);
  EXPECT_THROW(KeepGivenPixels(a, cv::Mat::zeros(4, 5, CV_16UC1)), Error);
  EXPECT_THROW(KeepGivenPixels(a, cv::Mat::zeros(4, 4, CV_8UC1)), Error);
}

// The realistic world's two captured performers touch from frame 6 of 10
// on: there the ground map alone holds one region for both. Played
// backwards, the shot starts with them touching, where no earlier frame
// holds them apart. On the union of their true silhouettes (one instance per
// view, the worst a detector can merge), the forward pass alone sees one
// person in those first frames; with PeopleFromTheNextFrame every frame has
// the two people.
TEST(PeopleFromTheNextFrameTest, PeopleWhoTouchAtTheStartOfAShotStayTwo) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const Capture capture = ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
      "next_people", synth::SmallRealisticOptions(data, 320, 180, 10))));
  std::vector<Camera> cameras;
  for (const CaptureView& v : capture.views) cameras.push_back(v.CameraAt(0));
  const int n = capture.num_frames;
  std::vector<std::vector<cv::Mat>> merged(n);  // shot frame k = capture frame n - 1 - k
  for (int k = 0; k < n; ++k)
    for (const CaptureView& v : capture.views) {
      const int t = n - 1 - k;
      const cv::Mat ids = ReadInstanceMask(capture.root / layout::GtInstances(v.name, t),
                                           capture.root / layout::GtInstancesInfo(v.name, t))
                              .ids;
      merged[k].push_back(cv::Mat(ids > 0) / 255);
    }
  const auto step = [&](int k, PeoplePositions start) {
    GroundPeopleFromDetections(cameras, merged[k], InitOptions(), &start);
    return start;
  };
  const std::vector<std::optional<PeoplePositions>> hints = PeopleFromTheNextFrame(n, step);
  PeoplePositions forward, both;
  int two_forward = 0, two_both = 0;
  for (int k = 0; k < n; ++k) {
    forward = step(k, forward);
    both = step(k, hints[k] ? *hints[k] : both);
    two_forward += forward.size() == 2;
    two_both += both.size() == 2;
  }
  std::printf("frames with two people: forwards %d, both ways %d of %d\n", two_forward, two_both,
              n);
  EXPECT_LT(two_forward, n);  // they do merge where the shot starts
  EXPECT_EQ(two_both, n);
}

// The objects preset's box (GT 3) and ball (GT 4), from their true
// silhouettes, with the ball given as part of its holder (GT 2) in every
// other view, as a detector merges them. The ball must be one object of its
// own, on the ball's pixels, with a depth range in the views where it was
// merged (the solve looks for it in the holder's pixels there), and never
// one object with the box: with the people's pixels where the views cannot
// tell and the classes given (DetectorContext).
TEST(ObjectsFromSparseTest, AnObjectMergedWithItsHolderInHalfTheViewsIsFound) {
  synth::SynthOptions o = synth::SynthPreset("objects");
  o.rig.image_width = 480;
  o.rig.image_height = 270;
  o.num_frames = 2;
  o.write_meshes = false;
  const Capture capture =
      ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir("merged_ball", o)));
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images, objects, people, gts;
  InstanceClasses classes;
  for (size_t v = 0; v < capture.views.size(); ++v) {
    const CaptureView& view = capture.views[v];
    cameras.push_back(view.CameraAt(0));
    images.push_back(ReadColorImage(capture.root / layout::Image(view.name, 0)));
    const cv::Mat gt = ReadLabelImage(capture.root / layout::GtInstances(view.name, 0));
    const bool merged = v % 2 == 1;
    cv::Mat obj = cv::Mat::zeros(gt.size(), CV_16U), ppl = obj.clone();
    obj.setTo(3, gt == 3);
    if (!merged) obj.setTo(4, gt == 4);
    ppl.setTo(1, gt == 1);
    ppl.setTo(2, merged ? (gt == 2) | (gt == 4) : gt == 2);
    objects.push_back(obj);
    people.push_back(ppl);
    gts.push_back(gt);
    classes.push_back({{3, "box"}, {4, "ball"}});
  }
  auto run = [&](const DetectorContext& detector) {
    ObjectLinker linker;
    linker.next_id = 3;
    return ObjectsFromSparse(cameras, images, objects, SparseFrameOptions{}, ObjectRegionOptions{},
                             &linker, false, detector);
  };
  // The object on most of the ball's pixels in the views that saw it apart
  // (0: none), and how many of the ball's and the box's pixels it holds.
  auto ball_object = [&](const FrameObjects& found, int* on_ball, int* on_box) {
    std::map<int, int> votes;
    for (size_t v = 0; v < gts.size(); v += 2)
      for (int y = 0; y < gts[v].rows; ++y)
        for (int x = 0; x < gts[v].cols; ++x)
          if (gts[v].at<uint16_t>(y, x) == 4) ++votes[found.ids[v].at<uint16_t>(y, x)];
    int id = 0, most = 0;
    for (const auto& [k, n] : votes)
      if (k != 0 && n > most) id = k, most = n;
    *on_ball = *on_box = 0;
    for (size_t v = 0; v < gts.size() && id != 0; v += 2) {
      *on_ball += cv::countNonZero((found.ids[v] == id) & (gts[v] == 4));
      *on_box += cv::countNonZero((found.ids[v] == id) & (gts[v] == 3));
    }
    return id;
  };
  int blind_ball = 0, blind_box = 0, ball = 0, box = 0;
  const FrameObjects blind = run({});
  const int blind_id = ball_object(blind, &blind_ball, &blind_box);
  const FrameObjects found = run({&classes, &people});
  const int id = ball_object(found, &ball, &box);
  int ranges_where_merged = 0;
  for (size_t v = 1; v < gts.size(); v += 2) ranges_where_merged += found.depth_ranges[v].count(id);
  int ball_pixels = 0;
  for (size_t v = 0; v < gts.size(); v += 2) ball_pixels += cv::countNonZero(gts[v] == 4);
  std::printf(
      "ball pixels of the views that saw it apart: %d; without the context object %d holds %d "
      "(and %d of the box), with it object %d holds %d (and %d of the box), with a depth range "
      "in %d of the %zu views where it was merged\n",
      ball_pixels, blind_id, blind_ball, blind_box, id, ball, box, ranges_where_merged,
      gts.size() / 2);
  ASSERT_NE(id, 0);
  EXPECT_GE(ball, 0.8 * ball_pixels);
  EXPECT_EQ(box, 0);
  EXPECT_GE(ranges_where_merged, static_cast<int>(gts.size() / 2) - 1);

  // The same objects added to the people (ids 1 and 2, with their depth
  // ranges): the people keep every pixel and range, the objects take ids
  // after theirs and the pixels the people leave.
  FrameObjects with_people;
  with_people.ids = people;
  with_people.depth_ranges.assign(people.size(), {{1, {3.0, 6.0}}, {2, {3.0, 6.0}}});
  ObjectLinker linker;
  linker.next_id = 3;
  const FrameObjects all =
      WithOtherObjects(with_people, cameras, images, people, objects, SparseFrameOptions{},
                       ObjectRegionOptions{}, &linker, &classes);
  for (size_t v = 0; v < people.size(); ++v) {
    EXPECT_EQ(cv::countNonZero((all.ids[v] != people[v]) & (people[v] != 0)), 0) << v;
    EXPECT_EQ(all.depth_ranges[v].count(1) + all.depth_ranges[v].count(2), 2u) << v;
    EXPECT_EQ(cv::countNonZero((all.ids[v] > 0) & (all.ids[v] < 3) & (people[v] == 0)), 0) << v;
  }
  EXPECT_EQ(all.centroids.size(), found.centroids.size());
  // Without other instances, the people unchanged.
  const std::vector<cv::Mat> none(objects.size(), cv::Mat());
  const FrameObjects alone =
      WithOtherObjects(with_people, cameras, images, people, none, SparseFrameOptions{},
                       ObjectRegionOptions{}, &linker, &classes);
  EXPECT_EQ(alone.centroids.size(), 0u);
  EXPECT_EQ(cv::countNonZero(alone.ids[0] != people[0]), 0);
}

// Across a cut (frames far apart in time) positions say nothing: each person
// takes back its id by the colours it wears (ObjectLinker::after_cut). The
// second frame's masks number the people the other way round, as a detector
// renumbering its instances would.
TEST(ObjectsFromSparseTest, AfterACutEachPersonTakesBackItsIdByItsColours) {
  synth::SynthOptions o = synth::SynthPreset("handshake");
  o.rig.image_width = 320;
  o.rig.image_height = 180;
  o.rig.num_views = 4;
  o.write_meshes = false;
  const Capture capture =
      ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir("reid_cut", o)));
  const int last = capture.num_frames - 1;
  auto frame = [&](int f, bool swap, ObjectLinker* linker) {
    std::vector<Camera> cameras;
    std::vector<cv::Mat> images, masks;
    for (const CaptureView& view : capture.views) {
      cameras.push_back(view.CameraAt(f));
      images.push_back(ReadColorImage(capture.root / layout::Image(view.name, f)));
      cv::Mat gt = ReadLabelImage(capture.root / layout::GtInstances(view.name, f));
      if (swap) gt = (gt == 1) / 255 * 2 + (gt == 2) / 255;
      gt.convertTo(gt, CV_16U);
      masks.push_back(gt);
    }
    return ObjectsFromSparse(cameras, images, masks, SparseFrameOptions{}, ObjectRegionOptions{},
                             linker, /*ids_alike_across_views=*/true);
  };
  // The id most of GT person `person`'s pixels take in view 0.
  auto id_of = [&](const FrameObjects& found, int f, int person) {
    const cv::Mat gt = ReadLabelImage(capture.root / layout::GtInstances(capture.views[0].name, f));
    std::map<int, int> votes;
    for (int y = 0; y < gt.rows; ++y)
      for (int x = 0; x < gt.cols; ++x)
        if (gt.at<uint16_t>(y, x) == person) ++votes[found.ids[0].at<uint16_t>(y, x)];
    votes.erase(0);
    int id = 0, most = 0;
    for (const auto& [k, n] : votes)
      if (n > most) id = k, most = n;
    return id;
  };
  ObjectLinker linker;
  const FrameObjects first = frame(0, false, &linker);
  CutLinker(&linker);
  const FrameObjects after = frame(last, true, &linker);
  for (int person : {1, 2}) {
    const int before_id = id_of(first, 0, person), after_id = id_of(after, last, person);
    std::printf("GT person %d: id %d at frame 0, id %d after the cut at frame %d\n", person,
                before_id, after_id, last);
    EXPECT_NE(before_id, 0);
    EXPECT_EQ(after_id, before_id) << "GT person " << person;
  }
  EXPECT_EQ(linker.next_id, 3);  // no new id
  // With re-identification off, a cut forgets every object.
  ObjectLinker forgetful;
  forgetful.options.max_appearance_distance = 0;
  frame(0, false, &forgetful);
  CutLinker(&forgetful);
  const FrameObjects anew = frame(last, true, &forgetful);
  EXPECT_GE(id_of(anew, last, 1), 3);
  EXPECT_GE(id_of(anew, last, 2), 3);
}

ObjectAppearance Wearing(Eigen::Vector3d upper, Eigen::Vector3d lower) {
  return {upper, lower, 1000};
}

// Across a cut, colours that do not single out one tracked person link
// nothing (ObjectLinkOptions::min_appearance_margin). Before the cut: A in a
// red shirt and jeans, B and C in dark clothes. After it: A again (1 Delta E
// off, as between instants under the same light) and two people who were
// not there before, D and E, dressed in dark clothes too (a studio's next
// take, the Panoptic demo's instants). D is 1.6 Delta E from B and 2.8
// from C: by colour it could be either or neither. Linked nearest first, D
// and E would take B's and C's ids, one id for two people each; A takes
// its id back either way.
TEST(LinkObjectsTest, AfterACutPeopleDressedAlikeTakeNewIdsAndADistinctOneItsOwn) {
  const ObjectAppearance a = Wearing({50, 60, 40}, {30, 0, -20});
  const ObjectAppearance b = Wearing({20, 0, 0}, {25, 0, 0});
  const ObjectAppearance c = Wearing({22, 2, -2}, {24, 1, 1});
  const std::map<int, Eigen::Vector3d> three = {
      {1, Eigen::Vector3d(0, 0, 0)}, {2, Eigen::Vector3d(1, 0, 0)}, {3, Eigen::Vector3d(2, 0, 0)}};
  auto run = [&](double margin) {
    ObjectLinker linker;
    linker.options.min_appearance_margin = margin;
    const std::map<int, int> before = LinkObjects(three, {{1, a}, {2, b}, {3, c}}, {}, &linker);
    CutLinker(&linker);
    const ObjectAppearance a_again = Wearing({51, 60, 40}, {31, 0, -20});
    const ObjectAppearance d = Wearing({21, 1, 1}, {26, 0, 1});
    const ObjectAppearance e = Wearing({23, -1, 0}, {24, 2, -1});
    const std::map<int, int> after =
        LinkObjects(three, {{1, d}, {2, a_again}, {3, e}}, {}, &linker);
    // Truth: after-cut object 2 is before-cut object 1; 1 and 3 are new.
    EXPECT_EQ(after.at(2), before.at(1));
    return std::pair(after.at(1), after.at(3));
  };
  const auto [d_id, e_id] = run(ObjectLinkOptions{}.min_appearance_margin);
  EXPECT_GT(d_id, 3) << "D took the id of a person seen before the cut";
  EXPECT_GT(e_id, 3) << "E took the id of a person seen before the cut";
  EXPECT_NE(d_id, e_id);
  // Nearest pairs first (margin 0) links both to the people in dark clothes.
  const auto [d_greedy, e_greedy] = run(0);
  EXPECT_LE(d_greedy, 3);
  EXPECT_LE(e_greedy, 3);
}

TEST(LinkObjectsTest, ANegativeMarginIsRefused) {
  ObjectLinkOptions options;
  options.min_appearance_margin = -1;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace u4d
