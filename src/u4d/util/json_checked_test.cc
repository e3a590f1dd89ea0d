#include "u4d/util/json_checked.h"

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

using nlohmann::json;
using test_util::ExpectErrorMentions;

TEST(JsonChecked, ReadsFieldsOfEachType) {
  const json j = json::parse(R"({"b": true, "i": -7, "big": 5000000000, "d": 2.5,
                                 "s": "x", "v": [1, 2], "vs": ["a"], "vv": [[0.5], []]})");
  EXPECT_TRUE(JsonRequired<bool>(j, "b", "f.json"));
  EXPECT_EQ(JsonRequired<int>(j, "i", "f.json"), -7);
  EXPECT_EQ(JsonRequired<int64_t>(j, "big", "f.json"), 5000000000LL);
  EXPECT_EQ(JsonRequired<double>(j, "d", "f.json"), 2.5);
  EXPECT_EQ(JsonRequired<double>(j, "i", "f.json"), -7.0);               // an integer is a number
  EXPECT_EQ(JsonRequired<int>(json{{"w", 960.0}}, "w", "f.json"), 960);  // an integral float
  EXPECT_EQ(JsonRequired<std::string>(j, "s", "f.json"), "x");
  EXPECT_EQ(JsonRequired<std::vector<int>>(j, "v", "f.json"), (std::vector<int>{1, 2}));
  EXPECT_EQ(JsonRequired<std::vector<std::string>>(j, "vs", "f.json"),
            std::vector<std::string>{"a"});
  EXPECT_EQ(JsonRequired<std::vector<std::vector<double>>>(j, "vv", "f.json"),
            (std::vector<std::vector<double>>{{0.5}, {}}));
  EXPECT_EQ(JsonOptional<int>(j, "absent", 42, "f.json"), 42);
  EXPECT_EQ(JsonOptional<std::string>(j, "s", "y", "f.json"), "x");
}

TEST(JsonChecked, MissingFieldNamesFileAndKey) {
  ExpectErrorMentions([] { JsonRequired<int>(json::object(), "fps", "cap.json"); },
                      {"cap.json", "missing field 'fps'"});
}

TEST(JsonChecked, WrongTypeNamesFileKeyAndValue) {
  const json j = json::parse(R"({"view": 7, "first_index": "3", "class": 2, "flag": 1})");
  ExpectErrorMentions([&] { JsonRequired<std::string>(j, "view", "c.json"); },
                      {"c.json", "'view'", "must be a string", "7"});
  ExpectErrorMentions([&] { JsonOptional<int>(j, "first_index", 0, "c.json"); },
                      {"c.json", "'first_index'", "must be an integer"});
  ExpectErrorMentions([&] { JsonOptional<std::string>(j, "class", "person", "m.json"); },
                      {"m.json", "'class'", "must be a string"});
  ExpectErrorMentions([&] { JsonRequired<bool>(j, "flag", "c.json"); },
                      {"'flag'", "true or false"});
  ExpectErrorMentions([&] { JsonRequired<std::vector<int>>(j, "view", "c.json"); },
                      {"'view'", "must be an array"});
}

TEST(JsonChecked, NotAnObjectIsAnError) {
  ExpectErrorMentions([] { JsonObject(json::array(), "capture.json"); },
                      {"capture.json", "expected a JSON object", "array"});
  ExpectErrorMentions([] { JsonRequired<int>(json(3), "num_frames", "capture.json"); },
                      {"capture.json", "expected a JSON object", "'num_frames'"});
  ExpectErrorMentions([] { JsonOptional<int>(json("s"), "k", 0, "x.json"); },
                      {"x.json", "expected a JSON object"});
}

TEST(JsonChecked, IntegersOutOfRangeOrFractionalAreErrors) {
  const json j = json::parse(R"({"big": 3000000000, "neg": -3000000000, "frac": 1.5,
                                 "huge": 18446744073709551615})");
  ExpectErrorMentions([&] { JsonRequired<int>(j, "big", "f.json"); },
                      {"f.json", "'big'", "out of range"});
  ExpectErrorMentions([&] { JsonRequired<int>(j, "neg", "f.json"); }, {"'neg'", "out of range"});
  ExpectErrorMentions([&] { JsonRequired<int>(j, "frac", "f.json"); },
                      {"'frac'", "must be an integer"});
  ExpectErrorMentions([&] { JsonRequired<int64_t>(j, "huge", "f.json"); },
                      {"'huge'", "out of range"});
  ExpectErrorMentions(
      [&] {
        JsonRequired<int>(json{{"f", 3e9}}, "f", "f.json");
      },
      {"'f'", "out of range"});
  ExpectErrorMentions([&] { JsonRequiredInt(j, "big", 1, 10, "f.json"); }, {"out of range"});
  const json k = json::parse(R"({"n": 11})");
  ExpectErrorMentions([&] { JsonRequiredInt(k, "n", 1, 10, "f.json"); },
                      {"f.json", "'n'", "[1, 10]", "11"});
}

TEST(JsonChecked, NonFiniteNumbersAreErrors) {
  json j;
  j["nan"] = std::nan("");
  j["inf"] = std::numeric_limits<double>::infinity();
  ExpectErrorMentions([&] { JsonRequired<double>(j, "nan", "f.json"); }, {"'nan'", "not finite"});
  ExpectErrorMentions(
      [&] {
        JsonRequired<std::vector<double>>(json{{"v", {1.0, j["inf"]}}}, "v", "f.json");
      },
      {"'v'[1]", "not finite"});
}

TEST(JsonChecked, ParseErrorsNameTheContext) {
  ExpectErrorMentions([] { ParseJsonText("{\"a\": [1, 2", "bad.json"); },
                      {"bad.json", "invalid JSON"});
  // A number that does not fit a double is nlohmann's out_of_range, not a
  // parse_error; it must still be a u4d::Error.
  ExpectErrorMentions([] { ParseJsonText("{\"fps\": 1e999}", "cap.json"); },
                      {"cap.json", "invalid JSON"});
  EXPECT_EQ(ParseJsonText("{\"a\": 1}", "ok.json")["a"], 1);
}

}  // namespace
}  // namespace u4d
