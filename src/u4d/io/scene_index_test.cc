#include "u4d/io/scene_index.h"

#include <gtest/gtest.h>

#include "u4d/io/layout.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

SceneIndex SmallIndex() {
  SceneIndex s;
  s.name = "handshake";
  s.fps = 25;
  s.frames = {0, 1, 2, 3, 4};
  s.views = {{"cam00", 160, 96}, {"cam01", 160, 96}};
  s.objects = {{1, "person", {31, 119, 180}}, {2, "person", {255, 127, 14}}};
  s.keyframes = {{0, {0, 1, 2}}, {3, {3, 4}}};
  s.segments = {{0, 0, 0, 2, "segments/00", {{1, "segments/00/1.glb"}}}};
  s.pictures = {"image", "instances", "depth"};
  s.has_meshes = true;
  s.has_poses3d = true;
  s.stages_done = {"masks"};
  return s;
}

TEST(SceneIndex, RoundTrip) {
  const fs::path dir = test_util::FreshTestDir("scene_index", "round_trip");
  const SceneIndex s = SmallIndex();
  WriteSceneIndex(dir, s);
  const SceneIndex r = ReadSceneIndex(dir);
  EXPECT_EQ(r.name, s.name);
  EXPECT_EQ(r.fps, s.fps);
  EXPECT_EQ(r.frames, s.frames);
  ASSERT_EQ(r.views.size(), 2u);
  EXPECT_EQ(r.views[1].name, "cam01");
  EXPECT_EQ(r.views[1].width, 160);
  ASSERT_EQ(r.objects.size(), 2u);
  EXPECT_EQ(r.objects[1].id, 2);
  EXPECT_EQ(r.objects[1].rgb, (std::array<uint8_t, 3>{255, 127, 14}));
  ASSERT_EQ(r.keyframes.size(), 2u);
  EXPECT_EQ(r.keyframes[1].members, (std::vector<int>{3, 4}));
  ASSERT_EQ(r.segments.size(), 1u);
  EXPECT_EQ(r.segments[0].last, 2);
  EXPECT_EQ(r.segments[0].glb.at(1), "segments/00/1.glb");
  EXPECT_EQ(r.pictures, s.pictures);
  EXPECT_TRUE(r.has_meshes);
  EXPECT_TRUE(r.has_poses3d);
  EXPECT_FALSE(r.has_tracks);
  EXPECT_FALSE(r.has_eval);
  EXPECT_EQ(r.stages_done, s.stages_done);
}

// The path templates the viewer reads must expand to io/layout.h's paths.
TEST(SceneIndex, FileTemplatesMatchLayout) {
  const nlohmann::json files = SceneIndexToJson(SmallIndex()).at("files");
  auto expand = [](std::string t, const std::string& key, const std::string& value) {
    const size_t p = t.find(key);
    return p == std::string::npos ? t : t.replace(p, key.size(), value);
  };
  std::string mesh = expand(files.at("mesh"), "{object}", "07");
  mesh = expand(mesh, "{frame}", "000042");
  EXPECT_EQ(fs::path(mesh), layout::SceneMesh(7, 42));
  std::string pic = expand(expand(files.at("picture"), "{kind}", "depth"), "{view}", "cam01");
  EXPECT_EQ(fs::path(expand(pic, "{frame}", "000003")), layout::ScenePicture("depth", "cam01", 3));
  EXPECT_EQ(fs::path(expand(files.at("poses3d"), "{frame}", "000003")), layout::ScenePoses3d(3));
  EXPECT_EQ(fs::path(expand(files.at("tracks"), "{view}", "cam00")), layout::SceneTracks("cam00"));
  EXPECT_EQ(fs::path(files.at("keyframes").get<std::string>()), layout::SceneKeyframes());
  EXPECT_EQ(fs::path(files.at("eval").get<std::string>()), layout::SceneEval());
  EXPECT_EQ(H36m17Bones().size(), 16u);
}

TEST(SceneIndex, BadInputNamesFileAndField) {
  const fs::path dir = test_util::FreshTestDir("scene_index", "bad");
  test_util::ExpectErrorMentions([&] { ReadSceneIndex(dir); }, {"scene.json"});

  auto write_and_read = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = SceneIndexToJson(SmallIndex());
    edit(j);
    WriteJsonFileAtomic(dir / "scene.json", j);
    return ReadSceneIndex(dir);
  };
  test_util::ExpectErrorMentions([&] { write_and_read([](auto& j) { j.erase("fps"); }); },
                                 {"scene.json", "fps"});
  test_util::ExpectErrorMentions([&] { write_and_read([](auto& j) { j["format"] = "x"; }); },
                                 {"scene.json", "format"});
  test_util::ExpectErrorMentions(
      [&] { write_and_read([](auto& j) { j["frames"] = {0, 2, 1}; }); },
      {"scene.json", "frames"});
  test_util::ExpectErrorMentions(
      [&] { write_and_read([](auto& j) { j["views"][0]["width"] = "wide"; }); },
      {"scene.json", "width"});
  test_util::ExpectErrorMentions(
      [&] { write_and_read([](auto& j) { j["objects"][0]["color"] = {1, 2, 300}; }); },
      {"scene.json", "color"});
  test_util::ExpectErrorMentions(
      [&] { write_and_read([](auto& j) { j["keyframes"][0]["frame"] = 9; }); },
      {"scene.json", "key-frame 9"});
  test_util::ExpectErrorMentions(
      [&] { write_and_read([](auto& j) { j["segments"][0]["first"] = 4; }); },
      {"scene.json", "segment 0"});

  SceneIndex bad = SmallIndex();
  bad.objects[1].id = 1;
  test_util::ExpectErrorMentions([&] { WriteSceneIndex(dir, bad); }, {"objects", "twice"});
}

}  // namespace
}  // namespace u4d
