#include "u4d/util/options.h"

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

enum class Colour { kRed, kBlue };

struct InnerOptions {
  double scale = 0.5;
  Colour colour = Colour::kRed;
};

struct OuterOptions {
  int count = 3;
  bool on = true;
  std::string name = "x";
  uint64_t seed = 7;
  int threads = 0;
  InnerOptions inner;
};

void DeclareOptions(OptionRegistry& r, InnerOptions* o) {
  r.Add("scale", &o->scale, "a scale");
  r.AddEnum("colour", &o->colour, {{"red", Colour::kRed}, {"blue", Colour::kBlue}}, "a colour");
}

void DeclareOptions(OptionRegistry& r, OuterOptions* o) {
  r.Add("count", &o->count, "how many");
  r.Add("on", &o->on, "a switch");
  r.Add("name", &o->name, "a name | with a bar");
  r.Add("seed", &o->seed, "a seed");
  r.Add("threads", &o->threads, "threads", OptionRole::kRunControl);
  r.Nested("inner", &o->inner);
}

using test_util::ExpectErrorMentions;

// A preset "look" that sets inner.scale and inner.colour.
OptionRegistry WithPreset(OuterOptions* o) {
  OptionRegistry r = OptionsOf(o);
  r.AddPreset(
      "look", {"small-red", "big-blue"},
      [o](const std::string& name) {
        o->inner.scale = name == "small-red" ? 0.5 : 2.0;
        o->inner.colour = name == "small-red" ? Colour::kRed : Colour::kBlue;
      },
      [o]() -> nlohmann::json {
        if (o->inner.scale == 0.5 && o->inner.colour == Colour::kRed) return "small-red";
        if (o->inner.scale == 2.0 && o->inner.colour == Colour::kBlue) return "big-blue";
        return nullptr;
      },
      "a look");
  return r;
}

// A preset sets its fields, is not in the JSON, goes before the explicit
// fields of the same object whatever their order, and refuses unknown names.
TEST(Options, PresetSetsItsFieldsBeforeTheExplicitOnes) {
  OuterOptions o;
  const OptionRegistry r = WithPreset(&o);
  EXPECT_TRUE(r.IsPreset("look"));
  EXPECT_FALSE(r.IsPreset("inner.scale"));
  EXPECT_FALSE(r.IsPreset("nothing"));
  EXPECT_EQ(r.Find("look")->get(), "small-red");
  EXPECT_FALSE(OptionsToJson(r).contains("look"));
  SetOptionFromText(r, "look", "big-blue", "--look");
  EXPECT_EQ(o.inner.scale, 2.0);
  EXPECT_EQ(o.inner.colour, Colour::kBlue);
  for (const nlohmann::json& j :
       {nlohmann::json::parse(R"({"inner": {"scale": 3}, "look": "small-red"})"),
        nlohmann::json::parse(R"({"look": "small-red", "inner": {"scale": 3}})")}) {
    o = OuterOptions();
    o.inner.colour = Colour::kBlue;
    UpdateOptionsFromJson(r, j, "c.json");
    EXPECT_EQ(o.inner.scale, 3.0) << j;
    EXPECT_EQ(o.inner.colour, Colour::kRed) << j;
    EXPECT_TRUE(r.Find("look")->get().is_null());
  }
  ExpectErrorMentions([&] { SetOptionFromText(r, "look", "plain", "--look"); },
                      {"--look", "'look'", "plain", "small-red, big-blue"});
  EXPECT_NE(OptionsMarkdown(r).find("| `look` | small-red \\| big-blue | `null` | (preset"),
            std::string::npos)
      << OptionsMarkdown(r);
}

TEST(Options, KeysAreDottedInDeclarationOrder) {
  OuterOptions o;
  const OptionRegistry r = OptionsOf(&o);
  std::vector<std::string> keys;
  for (const OptionEntry& e : r.Entries()) keys.push_back(e.key);
  EXPECT_EQ(keys, (std::vector<std::string>{"count", "on", "name", "seed", "threads", "inner.scale",
                                            "inner.colour"}));
  EXPECT_EQ(r.Find("inner.colour")->choices, (std::vector<std::string>{"red", "blue"}));
  EXPECT_EQ(r.Find("inner"), nullptr);
}

TEST(Options, ToJsonHoldsEveryFieldNested) {
  OuterOptions o;
  const nlohmann::json j = OptionsToJson(OptionsOf(&o));
  const nlohmann::json expected = {{"count", 3},   {"on", true},
                                   {"name", "x"},  {"seed", 7},
                                   {"threads", 0}, {"inner", {{"scale", 0.5}, {"colour", "red"}}}};
  EXPECT_EQ(j, expected);
  nlohmann::json result_only = expected;
  result_only.erase("threads");
  EXPECT_EQ(OptionsToJson(OptionsOf(&o), /*result_only=*/true), result_only);
}

TEST(Options, JsonRoundTrip) {
  OuterOptions a;
  a.count = 9, a.on = false, a.name = "y", a.seed = 123, a.threads = 4;
  a.inner.scale = 0.125, a.inner.colour = Colour::kBlue;
  const nlohmann::json j = OptionsToJson(OptionsOf(&a));
  OuterOptions b;
  UpdateOptionsFromJson(OptionsOf(&b), nlohmann::json::parse(j.dump()), "test");
  EXPECT_EQ(b.count, 9);
  EXPECT_FALSE(b.on);
  EXPECT_EQ(b.name, "y");
  EXPECT_EQ(b.seed, 123u);
  EXPECT_EQ(b.threads, 4);
  EXPECT_EQ(b.inner.scale, 0.125);
  EXPECT_EQ(b.inner.colour, Colour::kBlue);
}

TEST(Options, UpdateChangesOnlyTheGivenFields) {
  OuterOptions o;
  UpdateOptionsFromJson(OptionsOf(&o), {{"inner", {{"scale", 2}}}}, "test");
  EXPECT_EQ(o.inner.scale, 2.0);
  EXPECT_EQ(o.count, 3);
  EXPECT_EQ(o.inner.colour, Colour::kRed);
}

TEST(Options, UnknownKeysAndWrongTypesNameFileAndKey) {
  OuterOptions o;
  const OptionRegistry r = OptionsOf(&o);
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"inner", {{"sclae", 1}}}}, "c.json");
      },
      {"c.json", "unknown option 'inner.sclae'"});
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"count", "three"}}, "c.json");
      },
      {"c.json", "'count'", "integer"});
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"count", 2.5}}, "c.json");
      },
      {"'count'", "integer"});
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"on", 1}}, "c.json");
      },
      {"'on'", "true or false"});
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"inner", 5}}, "c.json");
      },
      {"c.json", "'inner'", "object"});
  ExpectErrorMentions(
      [&] {
        UpdateOptionsFromJson(r, {{"inner", {{"colour", "green"}}}}, "c");
      },
      {"'inner.colour'", "red, blue", "green"});
  ExpectErrorMentions([&] { UpdateOptionsFromJson(r, {{"seed", -1}}, "c"); }, {"'seed'", ">= 0"});
  ExpectErrorMentions([&] { UpdateOptionsFromJson(r, nlohmann::json::array(), "c.json"); },
                      {"c.json", "object"});
}

TEST(Options, SetFromText) {
  OuterOptions o;
  const OptionRegistry r = OptionsOf(&o);
  SetOptionAssignment(r, "inner.scale=1e-3", "--set");
  SetOptionAssignment(r, "on=false", "--set");
  SetOptionAssignment(r, "name=a=b", "--set");
  SetOptionFromText(r, "inner.colour", "blue", "--set");
  EXPECT_EQ(o.inner.scale, 1e-3);
  EXPECT_FALSE(o.on);
  EXPECT_EQ(o.name, "a=b");
  EXPECT_EQ(o.inner.colour, Colour::kBlue);
  ExpectErrorMentions([&] { SetOptionAssignment(r, "count", "--set"); }, {"--set", "key=value"});
  ExpectErrorMentions([&] { SetOptionAssignment(r, "cuont=1", "--set"); },
                      {"--set", "unknown option 'cuont'"});
  ExpectErrorMentions([&] { SetOptionAssignment(r, "count=x", "--set"); },
                      {"--set", "'count'", "number", "'x'"});
  ExpectErrorMentions([&] { SetOptionAssignment(r, "on=yes", "--set"); },
                      {"'on'", "true or false", "'yes'"});
}

TEST(Options, DeclaringAKeyTwiceThrows) {
  int a = 0, b = 0;
  OptionRegistry r;
  r.Add("a", &a, "");
  ExpectErrorMentions([&] { r.Add("a", &b, ""); }, {"'a'", "twice"});
}

TEST(Options, MarkdownTable) {
  OuterOptions o;
  const std::string md = OptionsMarkdown(OptionsOf(&o));
  EXPECT_EQ(md.substr(0, md.find('\n')), "| key | type | default | help |");
  EXPECT_NE(md.find("| `count` | int | `3` | how many |\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| `name` | string | `x` | a name \\| with a bar |\n"), std::string::npos);
  EXPECT_NE(md.find("| `inner.colour` | red \\| blue | `red` | a colour |\n"), std::string::npos);
  EXPECT_NE(md.find("| `threads` | int | `0` | (run control, not in the resume key) threads |"),
            std::string::npos);
}

}  // namespace
}  // namespace u4d
