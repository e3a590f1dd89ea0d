// The command line of the options of `u4d run`, shared by the benches that
// run the pipeline's stages: every option of RunOptions (DeclareOptions) can
// be set by
//
//   --config FILE     a JSON object with the keys of params.json (any subset;
//                     nested objects for nested structs), e.g.
//                     {"joint": {"rounds": 3, "weights": {"flow": 0.6}}}
//   --set KEY=VALUE   one option by its dotted key, e.g. --set joint.rounds=3
//                     (repeatable; `u4d options` lists the keys)
//   named flags       shorthands for common options (RunOptionFlags(): e.g.
//                     --working-width N is --set frame_setup.working_width=N)
//
// applied in that order, so a flag wins over --set and --set over the file;
// a preset (`ablation`: the joint.terms of a paper's ablation) is applied
// before the explicit options of its level (the file's keys; the command
// line's --set and flags), so an explicit joint.terms.* wins over it.
// A config file of the earlier format, {"weights": {...}, "terms": {...}}, is
// still read: "weights" replaces the paper's table (joint.weights with
// paper_weights false), "terms" sets joint.terms, and a params.json written
// when "ablation" was a field beside joint.terms gives the terms that ran
// (FromLegacyAblation). Errors (unknown key, wrong
// type) throw u4d::Error naming the file or flag and the dotted key; the
// values are checked by RunOptions::Check() where the options are used.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "u4d/pipeline/run_options.h"

namespace u4d {

// A named flag: a shorthand for one option.
struct OptionFlag {
  std::string flag;   // "--working-width"
  std::string key;    // "frame_setup.working_width"
  std::string value;  // empty: the flag takes a value; else a switch setting the key to this
};
// The named flags of `u4d run`.
const std::vector<OptionFlag>& RunOptionFlags();

// The overrides of one command line, applied to RunOptions by ApplyTo.
struct RunOverrides {
  std::string config;                                           // --config (empty = none)
  std::vector<std::string> assignments;                         // --set, in order
  std::vector<std::pair<OptionFlag, std::string>> named_flags;  // with their values, in order

  // The config file (its presets first), then the presets among the
  // assignments and named flags, then the other assignments, then the other
  // named flags.
  void ApplyTo(RunOptions* options) const;

  // For a hand-parsed command line (the benches): when argv[*i] is --config,
  // --set, a named flag or one of `extra_flags` (a bench's own shorthands),
  // records it with its value (argv[*i + 1]), moves *i to the last argument it
  // used and returns true; else returns false. Throws when the value is missing.
  bool Take(int argc, char** argv, int* i, const std::vector<OptionFlag>& extra_flags = {});
};

// The help of a named flag: the option's help from the registry and its key.
std::string OptionFlagHelp(const OptionFlag& flag);

// The value's type for a help line: INT, FLOAT, BOOL, TEXT or the enum's names.
std::string OptionFlagType(const OptionFlag& flag);

// Throws u4d::Error when `text` is not a valid value of the named flag's option
// (RunOptions::Check() of default options with that one value set).
void CheckOptionFlagValue(const OptionFlag& flag, const std::string& text);

// The text of docs/options.md: how options are set, the named flags and the
// table of every option with its default (OptionsMarkdown of RunOptions).
// `u4d options --markdown` prints it; a test keeps docs/options.md equal to it.
std::string RunOptionsMarkdown();

}  // namespace u4d
