#pragma once

#include "u4d/util/check.h"

namespace u4d {

template <typename T>
T JsonGet(const nlohmann::json& j, const std::string& key, const std::string& context) {
  U4D_CHECK(j.is_object(), "{}: expected a JSON object holding '{}'", context, key);
  auto it = j.find(key);
  U4D_CHECK(it != j.end(), "{}: missing field '{}'", context, key);
  try {
    return it->template get<T>();
  } catch (const nlohmann::json::exception& e) {
    ThrowError(fmt::format("{}: field '{}' has the wrong type ({})", context, key, e.what()));
  }
}

}  // namespace u4d
