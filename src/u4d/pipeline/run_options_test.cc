// RunOptions through the options registry: params.json holds every option,
// each key reaches its own field, and the resume key leaves out run control.
#include "u4d/pipeline/run_options.h"

#include <map>
#include <set>
#include <vector>

#include <fmt/ranges.h>

#include <gtest/gtest.h>

#include "u4d/joint/parameters.h"
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
  EXPECT_EQ(j.at("init").at("foreground").at("threshold_sigmas"), 4.0);
  EXPECT_EQ(j.at("init").at("people").at("box_fill"), "empty-views");
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
// the same options back. (Presets set other fields: PresetAblation* below.)
TEST(RunOptions, EveryKeyReachesItsOwnFieldAndRoundTrips) {
  RunOptions defaults;
  const nlohmann::json j0 = defaults.ToJson();
  RunOptions probe;
  const OptionRegistry registry = OptionsOf(&probe);
  ASSERT_GT(registry.Entries().size(), 240u);
  for (const OptionEntry& e : registry.Entries()) {
    if (e.role == OptionRole::kPreset) continue;
    const nlohmann::json before = e.get();
    e.set(OtherValue(e), "test");
    std::set<std::string> changed;
    DifferingKeys(j0, probe.ToJson(), "", &changed);
    EXPECT_EQ(changed, std::set<std::string>{e.key});
    e.set(before, "test");
  }
  for (const OptionEntry& e : registry.Entries())
    if (e.role != OptionRole::kPreset) e.set(OtherValue(e), "test");
  const nlohmann::json all_changed = probe.ToJson();
  RunOptions read;
  UpdateOptionsFromJson(OptionsOf(&read), nlohmann::json::parse(all_changed.dump()), "test");
  EXPECT_EQ(read.ToJson(), all_changed);
}

// The paper's ablations (Sec. 4.4) as sets of terms that are off.
std::map<std::string, std::set<std::string>> PaperAblations() {
  return {{"full", {}},          {"P_M", {"flow", "motion_reg"}},
          {"P_P", {"pose"}},     {"P_PM", {"pose", "flow", "motion_reg"}},
          {"P_S", {"semantic"}}, {"P_PS", {"pose", "semantic"}}};
}

std::set<std::string> TermsOff(const JointTerms& terms) {
  std::set<std::string> off;
  const nlohmann::json j = ToJson(terms);
  for (const auto& [name, on] : j.items())
    if (!on.get<bool>()) off.insert(name);
  return off;
}

// Options from a command line of `u4d run`'s overrides (after the program name).
RunOptions Apply(std::vector<std::string> args) {
  std::vector<char*> argv = {const_cast<char*>("u4d")};
  for (std::string& a : args) argv.push_back(a.data());
  RunOverrides overrides;
  for (int i = 1; i < static_cast<int>(argv.size()); ++i) {
    const bool taken = overrides.Take(static_cast<int>(argv.size()), argv.data(), &i);
    EXPECT_TRUE(taken) << argv[i];
  }
  RunOptions o;
  overrides.ApplyTo(&o);
  o.Check();
  return o;
}

// `ablation` is a preset: each name sets exactly the paper's terms, by the
// flag, --set and a config file, from any earlier terms; it is not a field of
// params.json (the terms it set are).
TEST(RunOptions, PresetAblationGivesThePapersTerms) {
  ASSERT_EQ(AblationNames().size(), PaperAblations().size());
  for (const auto& [name, off] : PaperAblations()) {
    EXPECT_EQ(TermsOff(AblationTerms(name)), off) << name;
    EXPECT_EQ(TermsOff(Apply({"--ablation", name}).joint.terms), off) << name;
    EXPECT_EQ(TermsOff(Apply({"--set", "ablation=" + name}).joint.terms), off) << name;
    RunOptions o;
    o.joint.terms.depth = o.joint.terms.smooth = false;  // replaced, not combined
    UpdateOptionsFromJson(OptionsOf(&o), {{"ablation", name}}, "c.json");
    EXPECT_EQ(TermsOff(o.joint.terms), off) << name;
    EXPECT_EQ(OptionsOf(&o).Find("ablation")->get(), name);
    EXPECT_FALSE(o.ToJson().contains("ablation"));
  }
  RunOptions o;
  o.joint.terms.depth = false;
  EXPECT_TRUE(OptionsOf(&o).Find("ablation")->get().is_null());  // the terms of no ablation
}

// An explicit joint.terms.* wins over the preset, before or after it on the
// command line and beside it in a config file; a later preset on the command
// line wins over the config file's terms.
TEST(RunOptions, ExplicitTermsWinOverThePresetAblation) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--ablation", "P_S", "--set", "joint.terms.semantic=true", "--set",
            "joint.terms.flow=false"},
           {"--set", "joint.terms.semantic=true", "--set", "joint.terms.flow=false", "--ablation",
            "P_S"},
           {"--set", "ablation=P_S", "--set", "joint.terms.semantic=true", "--set",
            "joint.terms.flow=false"},
       }) {
    const RunOptions o = Apply(args);
    EXPECT_EQ(TermsOff(o.joint.terms), std::set<std::string>{"flow"}) << fmt::format("{}", args);
    EXPECT_EQ(o.ToJson().at("joint").at("terms").at("flow"), false);  // params.json: what ran
  }
  RunOptions o;
  UpdateOptionsFromJson(
      OptionsOf(&o),
      {{"joint", {{"terms", {{"pose", true}, {"depth", false}}}}}, {"ablation", "P_PS"}}, "c.json");
  EXPECT_EQ(TermsOff(o.joint.terms), (std::set<std::string>{"depth", "semantic"}));

  const fs::path config = test_util::FreshTestDir("run_options", "preset_config") / "c.json";
  WriteTextFileAtomic(config, R"({"joint": {"terms": {"depth": false, "pose": false}}})");
  EXPECT_EQ(TermsOff(Apply({"--config", config.string(), "--ablation", "P_S"}).joint.terms),
            std::set<std::string>{"semantic"});
  EXPECT_EQ(
      TermsOff(Apply({"--config", config.string(), "--set", "joint.terms.flow=false"}).joint.terms),
      (std::set<std::string>{"depth", "pose", "flow"}));
}

TEST(RunOptions, UnknownPresetAblationIsRefusedByName) {
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"--ablation", "P_X"}, {"--set", "ablation=P_X"}})
    test_util::ExpectErrorMentions([&] { Apply(args); },
                                   {"'ablation'", "P_X", "full, P_M, P_P, P_PM, P_S, P_PS"});
  RunOptions o;
  test_util::ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(OptionsOf(&o), {{"ablation", "P_X"}}, "c.json");
      },
      {"c.json", "'ablation'", "P_X"});
  test_util::ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(OptionsOf(&o), {{"ablation", 3}}, "c.json");
      },
      {"c.json", "'ablation'"});
  EXPECT_EQ(o.joint.terms, JointTerms());
}

// params.json written when `ablation` was a field beside joint.terms (a term
// on when on in both): resuming compares, and --config reads, the terms that ran.
TEST(RunOptions, LegacyParamsAblationIsReadAsTheTermsThatRan) {
  nlohmann::json legacy = RunOptions().ToJson();
  legacy["ablation"] = "P_M";
  legacy["joint"]["terms"]["depth"] = false;
  RunOptions ran;
  ran.joint.terms = AblationTerms("P_M");
  ran.joint.terms.depth = false;
  EXPECT_EQ(RunOptions::ResumeKey(legacy), RunOptions::ResumeKey(ran.ToJson()));
  EXPECT_EQ(FromLegacyAblation(legacy), ran.ToJson());
  const fs::path config = test_util::FreshTestDir("run_options", "legacy_params") / "params.json";
  WriteTextFileAtomic(config, legacy.dump());
  EXPECT_EQ(Apply({"--config", config.string()}).joint.terms, ran.joint.terms);
  // A new file's "ablation" (not with all of joint.terms) is a preset.
  const nlohmann::json preset = {{"ablation", "P_M"}, {"joint", {{"terms", {{"flow", true}}}}}};
  EXPECT_EQ(FromLegacyAblation(preset), preset);
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
  o.init.foreground.threshold_sigmas = 5;
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
        UpdateOptionsFromJson(OptionsOf(&o), {{"init", {{"people", {{"box_fill", "some"}}}}}},
                              "c.json");
      },
      {"c.json", "'init.people.box_fill'", "never, empty-views, always"});
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
