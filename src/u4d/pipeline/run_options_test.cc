// RunOptions through the options registry: params.json holds every option,
// each key reaches its own field, and the resume key leaves out run control.
#include "u4d/pipeline/run_options.h"

#include <set>

#include <gtest/gtest.h>

#include "u4d/pipeline/run_flags.h"
#include "u4d/util/file.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// A value of entry `e` that differs from its current one.
nlohmann::json OtherValue(const OptionEntry& e) {
  const nlohmann::json v = e.get();
  if (e.type == "bool") return !v.get<bool>();
  if (e.type == "int") return v.get<int64_t>() + 1;
  if (e.type == "double") return v.get<double>() * 2 + 1;
  if (e.type == "enum") return v == e.choices.front() ? e.choices.back() : e.choices.front();
  return v.get<std::string>() + "x";
}

// The dotted keys whose values differ between two ToJson() objects.
void DifferingKeys(const nlohmann::json& a, const nlohmann::json& b, const std::string& prefix,
                   std::set<std::string>* out) {
  for (const auto& [key, value] : a.items()) {
    const std::string dotted = prefix.empty() ? key : prefix + "." + key;
    if (value.is_object())
      DifferingKeys(value, b.at(key), dotted, out);
    else if (value != b.at(key))
      out->insert(dotted);
  }
}

TEST(RunOptions, ParamsHoldOptionsThatWereOnceLeftOut) {
  const nlohmann::json j = RunOptions().ToJson();
  EXPECT_EQ(j.at("init").at("threshold_sigmas"), 4.0);
  EXPECT_EQ(j.at("init").at("box_fill"), "empty-views");
  EXPECT_EQ(j.at("background").at("max_frames"), 25);
  EXPECT_EQ(j.at("joint").at("labels").at("gmm_components"), 10);
  EXPECT_EQ(j.at("joint").at("motion_reg_boundary"), "ignore");
  EXPECT_EQ(j.at("joint").at("pose").at("limb_radius_m"), 0.06);
  EXPECT_FALSE(j.at("frame_setup").contains("pose"));  // one capsule model: joint.pose
  EXPECT_EQ(j.at("sparse").at("keypoints").at("max_features"), 4000);
  EXPECT_EQ(j.at("masks"), "auto");
  EXPECT_EQ(j.at("threads"), 0);
}

// Every key sets exactly its own field: changing one entry changes exactly
// that key of ToJson(), and the changed JSON read into default options gives
// the same options back.
TEST(RunOptions, EveryKeyReachesItsOwnFieldAndRoundTrips) {
  RunOptions defaults;
  const nlohmann::json j0 = defaults.ToJson();
  RunOptions probe;
  const OptionRegistry registry = OptionsOf(&probe);
  ASSERT_GT(registry.Entries().size(), 240u);
  for (const OptionEntry& e : registry.Entries()) {
    const nlohmann::json before = e.get();
    e.set(OtherValue(e), "test");
    std::set<std::string> changed;
    DifferingKeys(j0, probe.ToJson(), "", &changed);
    EXPECT_EQ(changed, std::set<std::string>{e.key});
    e.set(before, "test");
  }
  for (const OptionEntry& e : registry.Entries()) e.set(OtherValue(e), "test");
  const nlohmann::json all_changed = probe.ToJson();
  RunOptions read;
  UpdateOptionsFromJson(OptionsOf(&read), nlohmann::json::parse(all_changed.dump()), "test");
  EXPECT_EQ(read.ToJson(), all_changed);
}

TEST(RunOptions, ResumeKeyLeavesOutRunControlOnly) {
  RunOptions o;
  nlohmann::json params = o.ToJson();
  params["capture"] = "/some/capture";
  const nlohmann::json key = RunOptions::ResumeKey(params);
  for (const char* k : {"threads", "progress", "resume", "allow_empty", "evaluate"})
    EXPECT_FALSE(key.contains(k)) << k;
  EXPECT_EQ(key.at("capture"), "/some/capture");
  EXPECT_EQ(key.at("init"), params.at("init"));
  o.threads = 3;
  o.progress = false;
  EXPECT_EQ(RunOptions::ResumeKey(o.ToJson()), RunOptions::ResumeKey(RunOptions().ToJson()));
  o.init.threshold_sigmas = 5;
  EXPECT_NE(RunOptions::ResumeKey(o.ToJson()), RunOptions::ResumeKey(RunOptions().ToJson()));
}

TEST(RunOptions, UpdateFromJsonNamesTheFileAndTheDottedKey) {
  RunOptions o;
  test_util::ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(OptionsOf(&o), {{"joint", {{"weights", {{"flwo", 1}}}}}}, "c.json");
      },
      {"c.json", "unknown option 'joint.weights.flwo'"});
  test_util::ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(OptionsOf(&o), {{"init", {{"box_fill", "some"}}}}, "c.json");
      },
      {"c.json", "'init.box_fill'", "never, empty-views, always"});
}

// docs/options.md is generated (`u4d options --markdown > docs/options.md`);
// this fails when an option was added, renamed or changed its default or help
// without regenerating it.
TEST(RunOptions, DocsOptionsMdIsTheGeneratedText) {
  const fs::path doc = fs::path(U4D_SOURCE_DIR) / "docs" / "options.md";
  ASSERT_TRUE(fs::exists(doc)) << doc;
  EXPECT_TRUE(ReadTextFile(doc) == RunOptionsMarkdown())
      << doc.string() << " is stale: regenerate it with `u4d options --markdown > docs/options.md`";
}

// Every named flag of `u4d run` is a shorthand for a declared option.
TEST(RunOptions, NamedFlagsNameDeclaredOptions) {
  RunOptions o;
  const OptionRegistry registry = OptionsOf(&o);
  for (const OptionFlag& f : RunOptionFlags()) EXPECT_NE(registry.Find(f.key), nullptr) << f.flag;
  RunOverrides overrides;
  const char* argv[] = {"bench", "--working-width", "200",     "--no-resume",
                        "--set", "joint.rounds=3",  "--views", "2"};
  int i = 1;
  ASSERT_TRUE(overrides.Take(8, const_cast<char**>(argv), &i));
  ASSERT_TRUE(overrides.Take(8, const_cast<char**>(argv), &++i));
  ASSERT_TRUE(overrides.Take(8, const_cast<char**>(argv), &++i));
  EXPECT_EQ(i, 5);
  ++i;
  EXPECT_FALSE(overrides.Take(8, const_cast<char**>(argv), &i));  // not an option flag
  overrides.ApplyTo(&o);
  EXPECT_EQ(o.frame_setup.working_width, 200);
  EXPECT_FALSE(o.resume);
  EXPECT_EQ(o.joint.rounds, 3);
}

}  // namespace
}  // namespace u4d
