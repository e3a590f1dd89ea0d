#include "u4d/util/options.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "u4d/util/check.h"
#include "u4d/util/json_checked.h"

namespace u4d {
namespace {

// An entry reading and writing *field through the checked JSON conversions.
template <typename T>
OptionEntry Typed(T* field, const std::string& type) {
  OptionEntry e;
  e.type = type;
  e.get = [field]() -> nlohmann::json { return *field; };
  e.set = [field](const nlohmann::json& v, const std::string& where) {
    json_detail::Convert(v, where, field);
  };
  return e;
}

// "a.b.c" -> "a/b/c" (a JSON pointer's path; keys hold no '/' or '~').
std::string ReplaceDots(std::string key) {
  std::replace(key.begin(), key.end(), '.', '/');
  return key;
}

bool IsGroup(const OptionRegistry& registry, const std::string& key) {
  const std::string prefix = key + ".";
  for (const OptionEntry& e : registry.Entries())
    if (e.key.compare(0, prefix.size(), prefix) == 0) return true;
  return false;
}

// Sets the presets (presets true) or the other fields (false) found in `j`.
void UpdateGroup(const OptionRegistry& registry, const nlohmann::json& j, const std::string& prefix,
                 const std::string& context, bool presets) {
  U4D_CHECK(j.is_object(), "{}: {} must be a JSON object, found {}", context,
            prefix.empty() ? "the options" : fmt::format("option group '{}'", prefix),
            JsonDescribe(j));
  for (const auto& [name, value] : j.items()) {
    std::string key = prefix;
    if (!key.empty()) key += '.';
    key += name;
    if (const OptionEntry* e = registry.Find(key)) {
      if ((e->role == OptionRole::kPreset) == presets)
        e->set(value, fmt::format("{}: option '{}'", context, key));
      continue;
    }
    U4D_CHECK(IsGroup(registry, key), "{}: unknown option '{}' (`u4d options` lists them)", context,
              key);
    UpdateGroup(registry, value, key, context, presets);
  }
}

// Text as typed on a command line -> the JSON value for entry `e`.
nlohmann::json ValueFromText(const OptionEntry& e, const std::string& text,
                             const std::string& where) {
  if (e.type == "string" || e.type == "enum") return text;
  if (e.type == "bool") {
    if (text == "true" || text == "1") return true;
    if (text == "false" || text == "0") return false;
    ThrowError(fmt::format("{} must be true or false, got '{}'", where, text));
  }
  nlohmann::json v = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  U4D_CHECK(!v.is_discarded() && v.is_number(), "{} must be a number ({}), got '{}'", where, e.type,
            text);
  return v;
}

std::string EscapeCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string DefaultCell(const OptionEntry& e) {
  const nlohmann::json v = e.get();
  return v.is_string() ? v.get<std::string>() : v.dump();
}

}  // namespace

OptionRegistry::OptionRegistry() : entries_(std::make_shared<std::vector<OptionEntry>>()) {}

OptionRegistry::OptionRegistry(std::shared_ptr<std::vector<OptionEntry>> entries,
                               std::string prefix)
    : entries_(std::move(entries)), prefix_(std::move(prefix)) {}

OptionRegistry OptionRegistry::Group(const std::string& name) const {
  return OptionRegistry(entries_, prefix_ + name + ".");
}

void OptionRegistry::Add(const std::string& name, bool* field, const std::string& help,
                         OptionRole role) {
  AddEntry(Typed(field, "bool"), name, help, role);
}

void OptionRegistry::Add(const std::string& name, int* field, const std::string& help,
                         OptionRole role) {
  AddEntry(Typed(field, "int"), name, help, role);
}

void OptionRegistry::Add(const std::string& name, double* field, const std::string& help,
                         OptionRole role) {
  AddEntry(Typed(field, "double"), name, help, role);
}

void OptionRegistry::Add(const std::string& name, std::string* field, const std::string& help,
                         OptionRole role) {
  AddEntry(Typed(field, "string"), name, help, role);
}

void OptionRegistry::Add(const std::string& name, uint64_t* field, const std::string& help,
                         OptionRole role) {
  OptionEntry e;
  e.type = "int";
  e.get = [field]() -> nlohmann::json { return *field; };
  e.set = [field](const nlohmann::json& v, const std::string& where) {
    int64_t i = 0;
    json_detail::Convert(v, where, &i);
    U4D_CHECK(i >= 0, "{} must be >= 0, got {}", where, i);
    *field = static_cast<uint64_t>(i);
  };
  AddEntry(std::move(e), name, help, role);
}

void OptionRegistry::AddPreset(const std::string& name, std::vector<std::string> names,
                               std::function<void(const std::string&)> apply,
                               std::function<nlohmann::json()> current, const std::string& help) {
  OptionEntry e;
  e.type = "enum";
  e.choices = std::move(names);
  e.get = std::move(current);
  e.set = [apply = std::move(apply), choices = e.choices](const nlohmann::json& v,
                                                          const std::string& where) {
    const std::string text = v.is_string() ? v.get<std::string>() : v.dump();
    if (!v.is_string() || std::find(choices.begin(), choices.end(), text) == choices.end())
      ThrowUnknownName(where, text, choices);
    apply(text);
  };
  AddEntry(std::move(e), name, help, OptionRole::kPreset);
}

void OptionRegistry::AddEntry(OptionEntry entry, const std::string& name, const std::string& help,
                              OptionRole role) {
  entry.key = prefix_ + name;
  entry.help = help;
  entry.role = role;
  U4D_CHECK(Find(entry.key) == nullptr, "option '{}' is declared twice", entry.key);
  entries_->push_back(std::move(entry));
}

const OptionEntry* OptionRegistry::Find(const std::string& key) const {
  for (const OptionEntry& e : *entries_)
    if (e.key == key) return &e;
  return nullptr;
}

bool OptionRegistry::IsPreset(const std::string& key) const {
  const OptionEntry* e = Find(key);
  return e != nullptr && e->role == OptionRole::kPreset;
}

void OptionRegistry::ThrowUnknownName(const std::string& where, const std::string& value,
                                      const std::vector<std::string>& names) {
  ThrowError(fmt::format("{} must be one of {}, got {}", where, fmt::join(names, ", "), value));
}

nlohmann::json OptionsToJson(const OptionRegistry& registry, bool result_only) {
  nlohmann::json out = nlohmann::json::object();
  for (const OptionEntry& e : registry.Entries()) {
    if (e.role == OptionRole::kPreset || (result_only && e.role != OptionRole::kResult)) continue;
    nlohmann::json* node = &out;
    size_t begin = 0;
    for (size_t dot = e.key.find('.'); dot != std::string::npos; dot = e.key.find('.', begin)) {
      node = &(*node)[e.key.substr(begin, dot - begin)];
      begin = dot + 1;
    }
    (*node)[e.key.substr(begin)] = e.get();
  }
  return out;
}

void EraseRunControlOptions(const OptionRegistry& registry, nlohmann::json* j) {
  for (const OptionEntry& e : registry.Entries()) {
    if (e.role != OptionRole::kRunControl) continue;
    const nlohmann::json::json_pointer pointer("/" + ReplaceDots(e.key));
    if (!j->contains(pointer)) continue;
    nlohmann::json& parent = (*j)[pointer.parent_pointer()];
    if (parent.is_object()) parent.erase(pointer.back());
  }
}

void UpdateOptionsFromJson(const OptionRegistry& registry, const nlohmann::json& j,
                           const std::string& context) {
  UpdateGroup(registry, j, "", context, /*presets=*/true);
  UpdateGroup(registry, j, "", context, /*presets=*/false);
}

void SetOptionFromText(const OptionRegistry& registry, const std::string& key,
                       const std::string& text, const std::string& context) {
  const OptionEntry* e = registry.Find(key);
  U4D_CHECK(e != nullptr, "{}: unknown option '{}' (`u4d options` lists them)", context, key);
  const std::string where = fmt::format("{}: option '{}'", context, key);
  e->set(ValueFromText(*e, text, where), where);
}

void SetOptionAssignment(const OptionRegistry& registry, const std::string& assignment,
                         const std::string& context) {
  const size_t eq = assignment.find('=');
  U4D_CHECK(eq != std::string::npos && eq > 0, "{}: expected key=value, got '{}'", context,
            assignment);
  SetOptionFromText(registry, assignment.substr(0, eq), assignment.substr(eq + 1), context);
}

std::string OptionsMarkdown(const OptionRegistry& registry) {
  std::string out = "| key | type | default | help |\n|---|---|---|---|\n";
  for (const OptionEntry& e : registry.Entries()) {
    const std::string type =
        e.type == "enum" ? fmt::format("{}", fmt::join(e.choices, " \\| ")) : e.type;
    const std::string help = e.role == OptionRole::kRunControl
                                 ? "(run control, not in the resume key) " + e.help
                             : e.role == OptionRole::kPreset
                                 ? "(preset, not in params.json: the options it sets are) " + e.help
                                 : e.help;
    out +=
        fmt::format("| `{}` | {} | `{}` | {} |\n", e.key, type, DefaultCell(e), EscapeCell(help));
  }
  return out;
}

}  // namespace u4d
