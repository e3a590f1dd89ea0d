// The options registry: every XxxOptions struct lists its fields once, in a
// function beside its Check(),
//
//   void DeclareOptions(OptionRegistry& r, FrameSetupOptions* o) {
//     r.Add("working_width", &o->working_width, "the optimisation runs at this width");
//     r.Nested("pose", &o->pose);  // calls DeclareOptions(PosePriorOptions*) with prefix "pose."
//   }
//
// and everything else comes from that one list: the complete JSON of the
// options (OptionsToJson), overriding any field from JSON (UpdateOptionsFromJson,
// `--config file.json`) or from "key=value" text (SetOptionFromText, `--set`),
// and the Markdown table of docs/options.md (OptionsMarkdown). The default of a
// field is its initialiser in the struct; the registry holds pointers into one
// struct instance and reads and writes it directly.
//
// Keys are dotted paths of the nested structs ("joint.weights.flow"). Values
// are JSON booleans, numbers (integers must be integral and in range) and
// strings; an enum is a string from its fixed list of names. Every error
// throws u4d::Error naming the context (usually the file or the flag), the
// dotted key and what was found. Overriding never calls Check(): callers check
// the whole options struct after all overrides.
//
// A field is either result-changing (the default) or run control
// (OptionRole::kRunControl: threads, progress bars, ...): both are written to
// params.json, only the first are compared when a run resumes.
//
// A preset (AddPreset, OptionRole::kPreset) is a name that sets other fields
// (e.g. `ablation` sets the joint.terms booleans). It holds no value of its
// own: it is not written to params.json (the fields it set are), and
// UpdateOptionsFromJson applies the presets of a JSON object before its other
// keys, so a field set explicitly in the same object wins over a preset.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace u4d {

enum class OptionRole {
  kResult,      // changes what a run computes
  kRunControl,  // changes only how it runs (threads, progress, resume)
  kPreset,      // sets other fields; not stored itself (AddPreset)
};

// One field of an options struct.
struct OptionEntry {
  std::string key;                   // dotted path, e.g. "joint.weights.flow"
  std::string type;                  // "bool", "int", "double", "string", or "enum"
  std::vector<std::string> choices;  // enum: the accepted names
  std::string help;
  OptionRole role = OptionRole::kResult;
  std::function<nlohmann::json()> get;
  // Converts and stores `value`; throws naming `where` when it does not fit.
  std::function<void(const nlohmann::json& value, const std::string& where)> set;
};

// A list of OptionEntry with a key prefix. Nested() and Group() return views
// that share the parent's list, so a whole tree of structs lands in one flat
// list in declaration order. Declaring a key twice throws (a bug).
class OptionRegistry {
 public:
  OptionRegistry();

  void Add(const std::string& name, bool* field, const std::string& help,
           OptionRole role = OptionRole::kResult);
  void Add(const std::string& name, int* field, const std::string& help,
           OptionRole role = OptionRole::kResult);
  void Add(const std::string& name, uint64_t* field, const std::string& help,
           OptionRole role = OptionRole::kResult);
  void Add(const std::string& name, double* field, const std::string& help,
           OptionRole role = OptionRole::kResult);
  void Add(const std::string& name, std::string* field, const std::string& help,
           OptionRole role = OptionRole::kResult);

  // A preset: setting it to one of `names` calls apply(name), which sets
  // other fields; get() is current(): the name whose settings the fields hold
  // now, or null. An unknown name throws, naming the key, it and `names`.
  void AddPreset(const std::string& name, std::vector<std::string> names,
                 std::function<void(const std::string&)> apply,
                 std::function<nlohmann::json()> current, const std::string& help);

  // An enum stored as one of `names` (name, value) in JSON and on the command line.
  template <typename E>
  void AddEnum(const std::string& name, E* field, std::vector<std::pair<std::string, E>> names,
               const std::string& help, OptionRole role = OptionRole::kResult);

  // The fields of a nested options struct under "name.": DeclareOptions(group, options),
  // found by argument-dependent lookup.
  template <typename T>
  void Nested(const std::string& name, T* options) {
    OptionRegistry group = Group(name);
    DeclareOptions(group, options);
  }
  OptionRegistry Group(const std::string& name) const;

  const std::vector<OptionEntry>& Entries() const { return *entries_; }
  // nullptr when no field has this dotted key.
  const OptionEntry* Find(const std::string& key) const;
  // Whether `key` names a preset (AddPreset).
  bool IsPreset(const std::string& key) const;

 private:
  OptionRegistry(std::shared_ptr<std::vector<OptionEntry>> entries, std::string prefix);
  void AddEntry(OptionEntry entry, const std::string& name, const std::string& help,
                OptionRole role);
  // Throws naming the field and the accepted names.
  [[noreturn]] static void ThrowUnknownName(const std::string& where, const std::string& value,
                                            const std::vector<std::string>& names);

  std::shared_ptr<std::vector<OptionEntry>> entries_;
  std::string prefix_;  // "" or "a.b."
};

// The registry of one options struct (holding pointers into *options).
template <typename T>
OptionRegistry OptionsOf(T* options) {
  OptionRegistry r;
  DeclareOptions(r, options);
  return r;
}

// Every field (or only the result-changing ones) as nested JSON objects;
// presets are left out (they hold no value of their own).
nlohmann::json OptionsToJson(const OptionRegistry& registry, bool result_only = false);

// Removes the run-control fields (OptionRole::kRunControl) from `j`, JSON as
// written by OptionsToJson (other keys are left alone; absent ones are fine).
void EraseRunControlOptions(const OptionRegistry& registry, nlohmann::json* j);

// Overrides the fields present in the object `j` (nested objects for nested
// structs; absent fields keep their values): first the presets in `j`, then
// its other keys, so an explicit field wins over a preset. An unknown key or a value of the
// wrong type throws, naming `context` and the dotted key.
void UpdateOptionsFromJson(const OptionRegistry& registry, const nlohmann::json& j,
                           const std::string& context);

// Sets one field from text as typed on a command line: "true"/"false" for a
// bool, a number, or a string/enum name as is. Throws naming `context` and the
// key on an unknown key or text that does not fit the type.
void SetOptionFromText(const OptionRegistry& registry, const std::string& key,
                       const std::string& text, const std::string& context);
// "key=value" (as `--set key=value`); throws on text without '='.
void SetOptionAssignment(const OptionRegistry& registry, const std::string& assignment,
                         const std::string& context);

// A Markdown table of every field: key, type, default (the current value,
// i.e. the default when the registry holds a default-constructed struct), help.
std::string OptionsMarkdown(const OptionRegistry& registry);

template <typename E>
void OptionRegistry::AddEnum(const std::string& name, E* field,
                             std::vector<std::pair<std::string, E>> names, const std::string& help,
                             OptionRole role) {
  OptionEntry e;
  e.type = "enum";
  for (const auto& n : names) e.choices.push_back(n.first);
  e.get = [field, names]() -> nlohmann::json {
    for (const auto& [text, value] : names)
      if (value == *field) return text;
    return nullptr;  // a value with no name (never for a complete list)
  };
  e.set = [field, names, choices = e.choices](const nlohmann::json& v, const std::string& where) {
    const std::string text = v.is_string() ? v.get<std::string>() : v.dump();
    for (const auto& [n, value] : names)
      if (v.is_string() && n == text) {
        *field = value;
        return;
      }
    ThrowUnknownName(where, text, choices);
  };
  AddEntry(std::move(e), name, help, role);
}

}  // namespace u4d
