// Checked access to JSON read from files. Every failure throws u4d::Error
// naming `context` (usually the file), the key and what was found, so no
// nlohmann exception (type error, missing key, number overflow) escapes a
// reader. Numbers are checked: doubles must be finite, integers must be
// integral (960 or 960.0) and within the range of the target type.
//
//   const json& m = JsonObject(doc, "capture.json");
//   int n = JsonRequired<int>(m, "num_frames", "capture.json");
//   std::string s = JsonOptional<std::string>(m, "scene", "indoor", "capture.json");
//
// Supported types: bool, int, int64_t, double, std::string, nlohmann::json
// (any value) and std::vector of any of these.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/util/check.h"

namespace u4d {

// Parses JSON text; a syntax error or a number that does not fit a double
// (e.g. 1e999) throws u4d::Error naming `context` and the position.
nlohmann::json ParseJsonText(const std::string& text, const std::string& context);

// Returns `j`; throws unless it is a JSON object.
const nlohmann::json& JsonObject(const nlohmann::json& j, const std::string& context);

// A short description of a JSON value for error messages: its type and, for
// scalars, its text (truncated).
std::string JsonDescribe(const nlohmann::json& v);

namespace json_detail {
// `where` names the value, e.g. "capture.json: field 'fps'".
void Convert(const nlohmann::json& v, const std::string& where, bool* out);
void Convert(const nlohmann::json& v, const std::string& where, int* out);
void Convert(const nlohmann::json& v, const std::string& where, int64_t* out);
void Convert(const nlohmann::json& v, const std::string& where, double* out);
void Convert(const nlohmann::json& v, const std::string& where, std::string* out);
void Convert(const nlohmann::json& v, const std::string& where, nlohmann::json* out);

template <typename T>
void Convert(const nlohmann::json& v, const std::string& where, std::vector<T>* out) {
  U4D_CHECK(v.is_array(), "{} must be an array, found {}", where, JsonDescribe(v));
  out->clear();
  out->reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    T x{};
    Convert(v[i], fmt::format("{}[{}]", where, i), &x);
    out->push_back(std::move(x));
  }
}
}  // namespace json_detail

// Converts one value; `what` names it in errors (e.g. "'K' entry").
template <typename T>
T JsonAs(const nlohmann::json& v, const std::string& context, const std::string& what) {
  T out{};
  json_detail::Convert(v, fmt::format("{}: {}", context, what), &out);
  return out;
}

// The field `key` of the object `obj`; throws when `obj` is not an object,
// the key is missing or the value does not convert to T.
template <typename T>
T JsonRequired(const nlohmann::json& obj, const std::string& key, const std::string& context) {
  U4D_CHECK(obj.is_object(), "{}: expected a JSON object holding '{}', found {}", context, key,
            JsonDescribe(obj));
  const auto it = obj.find(key);
  U4D_CHECK(it != obj.end(), "{}: missing field '{}'", context, key);
  return JsonAs<T>(*it, context, fmt::format("field '{}'", key));
}

// As JsonRequired, but returns `fallback` when the key is absent (or null).
template <typename T>
T JsonOptional(const nlohmann::json& obj, const std::string& key, const T& fallback,
               const std::string& context) {
  U4D_CHECK(obj.is_object(), "{}: expected a JSON object holding '{}', found {}", context, key,
            JsonDescribe(obj));
  const auto it = obj.find(key);
  if (it == obj.end() || it->is_null()) return fallback;
  return JsonAs<T>(*it, context, fmt::format("field '{}'", key));
}

// An integer field within [lo, hi]; the error names the range.
int JsonRequiredInt(const nlohmann::json& obj, const std::string& key, int lo, int hi,
                    const std::string& context);

}  // namespace u4d
