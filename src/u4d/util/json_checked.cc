#include "u4d/util/json_checked.h"

#include <cmath>
#include <limits>

namespace u4d {

nlohmann::json ParseJsonText(const std::string& text, const std::string& context) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // parse_error for syntax, out_of_range (406) for a number like 1e999.
    ThrowError(fmt::format("{}: invalid JSON ({})", context, e.what()));
  }
}

const nlohmann::json& JsonObject(const nlohmann::json& j, const std::string& context) {
  U4D_CHECK(j.is_object(), "{}: expected a JSON object, found {}", context, JsonDescribe(j));
  return j;
}

std::string JsonDescribe(const nlohmann::json& v) {
  if (v.is_object()) return "an object";
  if (v.is_array()) return fmt::format("an array of {}", v.size());
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 40) + "...";
  return fmt::format("{} {}", v.type_name(), text);
}

namespace json_detail {
namespace {

// The value of an integer JSON number as int64, or an error naming `where`.
// A float with an integral value (960.0, as some writers emit) is accepted.
int64_t Integer(const nlohmann::json& v, const std::string& where) {
  if (v.is_number_float()) {
    const double d = v.get<double>();
    U4D_CHECK(std::isfinite(d) && d == std::trunc(d), "{} must be an integer, found {}", where,
              JsonDescribe(v));
    U4D_CHECK(std::abs(d) < 9.2e18, "{} is out of range ({})", where, d);
    return static_cast<int64_t>(d);
  }
  U4D_CHECK(v.is_number_integer(), "{} must be an integer, found {}", where, JsonDescribe(v));
  if (v.is_number_unsigned()) {
    const uint64_t u = v.get<uint64_t>();
    U4D_CHECK(u <= static_cast<uint64_t>(std::numeric_limits<int64_t>::max()),
              "{} is out of range ({})", where, u);
    return static_cast<int64_t>(u);
  }
  return v.get<int64_t>();
}

}  // namespace

void Convert(const nlohmann::json& v, const std::string& where, bool* out) {
  U4D_CHECK(v.is_boolean(), "{} must be true or false, found {}", where, JsonDescribe(v));
  *out = v.get<bool>();
}

void Convert(const nlohmann::json& v, const std::string& where, int* out) {
  const int64_t i = Integer(v, where);
  U4D_CHECK(i >= std::numeric_limits<int>::min() && i <= std::numeric_limits<int>::max(),
            "{} is out of range ({})", where, i);
  *out = static_cast<int>(i);
}

void Convert(const nlohmann::json& v, const std::string& where, int64_t* out) {
  *out = Integer(v, where);
}

void Convert(const nlohmann::json& v, const std::string& where, double* out) {
  U4D_CHECK(v.is_number(), "{} must be a number, found {}", where, JsonDescribe(v));
  const double d = v.get<double>();
  U4D_CHECK(std::isfinite(d), "{} is not finite", where);
  *out = d;
}

void Convert(const nlohmann::json& v, const std::string& where, std::string* out) {
  U4D_CHECK(v.is_string(), "{} must be a string, found {}", where, JsonDescribe(v));
  *out = v.get<std::string>();
}

void Convert(const nlohmann::json& v, const std::string& /*where*/, nlohmann::json* out) {
  *out = v;
}

}  // namespace json_detail

int JsonRequiredInt(const nlohmann::json& obj, const std::string& key, int lo, int hi,
                    const std::string& context) {
  const int v = JsonRequired<int>(obj, key, context);
  U4D_CHECK(v >= lo && v <= hi, "{}: field '{}' must be in [{}, {}], found {}", context, key, lo,
            hi, v);
  return v;
}

}  // namespace u4d
