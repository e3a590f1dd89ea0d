#pragma once

#include "u4d/util/json_checked.h"

namespace u4d {

template <typename T>
T JsonGet(const nlohmann::json& j, const std::string& key, const std::string& context) {
  return JsonRequired<T>(j, key, context);
}

}  // namespace u4d
