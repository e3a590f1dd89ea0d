// Classes carried from the detector's instances to the objects, on hand-made
// masks whose true classes are known.
#include "u4d/pipeline/object_classes.h"

#include <gtest/gtest.h>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/file.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// A 4x6 view: object 1 on columns 0-2, object 2 on columns 3-5.
cv::Mat TwoObjects() {
  cv::Mat ids = cv::Mat::zeros(4, 6, CV_16U);
  ids.colRange(0, 3).setTo(1);
  ids.colRange(3, 6).setTo(2);
  return ids;
}

// Detector instances: id 5 on columns 0-1, id 7 on columns 2-5, with classes.
InstanceMask Detections(const std::string& class5, const std::string& class7) {
  InstanceMask m;
  m.ids = cv::Mat::zeros(4, 6, CV_16U);
  m.ids.colRange(0, 2).setTo(5);
  m.ids.colRange(2, 6).setTo(7);
  m.instances = {{5, class5, 0.9}, {7, class7, 0.8}};
  return m;
}

TEST(ObjectClassesTest, EachObjectVotesForTheClassUnderMostOfItsPixels) {
  // Object 1 is 2/3 class5, 1/3 class7; object 2 is all class7.
  const ClassVotes votes =
      VoteObjectClasses({TwoObjects(), TwoObjects(), cv::Mat()},
                        {Detections("person", "box"), Detections("box", "box"), InstanceMask{}});
  ASSERT_EQ(votes.size(), 2u);
  EXPECT_EQ(votes.at(1), (std::map<std::string, int>{{"person", 1}, {"box", 1}}));
  EXPECT_EQ(votes.at(2), (std::map<std::string, int>{{"box", 2}}));
  // Background detector pixels do not vote: an object over background only has no vote.
  InstanceMask empty;
  empty.ids = cv::Mat::zeros(4, 6, CV_16U);
  EXPECT_TRUE(VoteObjectClasses({TwoObjects()}, {empty}).empty());
}

TEST(ObjectClassesTest, TheMajorityOverViewsAndFramesWins) {
  ClassVotes total;
  AddClassVotes({{1, {{"box", 2}, {"person", 1}}}, {2, {{"person", 3}}}}, &total);
  AddClassVotes(
      {{1, {{"box", 1}}}, {3, {{"chair", 1}, {"person", 1}}}, {4, {{"chair", 2}, {"ball", 2}}}},
      &total);
  const std::map<int, std::string> classes = MajorityClasses(total);
  EXPECT_EQ(classes.at(1), "box");     // 3 box against 1 person
  EXPECT_EQ(classes.at(2), "person");  // unanimous
  EXPECT_EQ(classes.at(3), "person");  // a tie goes to person
  EXPECT_EQ(classes.at(4), "ball");    // a tie without person: alphabetically first
  EXPECT_EQ(ObjectClass(classes, 1), "box");
  EXPECT_EQ(ObjectClass(classes, 9), "person");  // no vote: a person
  EXPECT_TRUE(IsPersonClass(ObjectClass(classes, 9)));
  EXPECT_FALSE(IsPersonClass("box"));
}

TEST(ObjectClassesTest, VotesRoundTripThroughTheFrameFilesAndBadOnesThrow) {
  const fs::path scene = test_util::FreshTestDir("object_classes", "scene");
  const ClassVotes f0 = {{1, {{"box", 2}}}, {2, {{"person", 2}}}};
  const ClassVotes f1 = {{1, {{"person", 1}}}, {2, {{"person", 1}}}};
  EXPECT_EQ(ClassVotesFromJson(ClassVotesToJson(f0), "t"), f0);
  WriteJsonFileAtomic(scene / layout::SceneInitialObjects(0), {{"classes", ClassVotesToJson(f0)}});
  WriteJsonFileAtomic(scene / layout::SceneInitialObjects(1), {{"classes", ClassVotesToJson(f1)}});
  WriteJsonFileAtomic(scene / layout::SceneInitialObjects(2), {{"frame", 2}});  // older file
  const std::map<int, std::string> classes = ReadRunObjectClasses(scene, 0, 3);
  EXPECT_EQ(classes, (std::map<int, std::string>{{1, "box"}, {2, "person"}}));

  EXPECT_THROW(ClassVotesFromJson(nlohmann::json::array(), "t"), Error);
  EXPECT_THROW(ClassVotesFromJson({{"x", {{"box", 1}}}}, "t"), Error);
  EXPECT_THROW(ClassVotesFromJson({{"0", {{"box", 1}}}}, "t"), Error);
  EXPECT_THROW(ClassVotesFromJson({{"1", {{"box", 0}}}}, "t"), Error);
  EXPECT_THROW(ClassVotesFromJson({{"1", {{"box", "many"}}}}, "t"), Error);
  EXPECT_THROW(ReadRunObjectClasses(scene, 0, 4), Error);  // frame 3 was never written
  EXPECT_THROW(VoteObjectClasses({TwoObjects()}, {}), Error);
  EXPECT_THROW(VoteObjectClasses({cv::Mat::zeros(3, 6, CV_16U)}, {Detections("a", "b")}), Error);
}

}  // namespace
}  // namespace u4d
