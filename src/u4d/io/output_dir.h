// The output folder of a command (`u4d run -o`, `u4d synth -o`,
// `u4d export-viewer -o`), checked before any work so that a bad choice
// fails in a second with a message, not after the run:
//  - it is a directory or does not exist yet (it is then created);
//  - it is writable (a probe file is created and removed);
//  - it is not an input of the command (a scene written into its capture
//    would be read back as input by the next run), nor inside one unless the
//    input allows subfolders (a run may write <capture>/scene);
//  - it is empty, or a previous output of the same command (it holds one of
//    `markers`), or `force` is set.
// Every failure, filesystem errors included, is a u4d::Error naming the flag
// and the path.
#pragma once

#include <string>
#include <vector>

#include "u4d/util/file.h"

namespace u4d {

struct OutputDirOptions {
  // The option naming the folder, used in messages ("--output").
  std::string flag = "--output";
  // The command, used in messages ("u4d run").
  std::string command;
  // Folders the command reads; the output may not equal or lie inside one.
  std::vector<fs::path> inputs;
  // Folders the command reads whose subfolders it never reads; the output may
  // not equal one but may lie inside it.
  std::vector<fs::path> input_roots;
  // Names (files or folders) whose presence marks a previous output of the
  // same command, e.g. "run.json"; such a folder is accepted.
  std::vector<std::string> markers;
  // Accept a non-empty folder without a marker.
  bool force = false;
  // The flag that sets `force`, suggested in the message ("" = none).
  std::string force_flag;

  void Check() const;
};

// What CheckOutputDir found.
enum class OutputDirState { kCreated, kEmpty, kPreviousOutput, kForced };

// Checks `dir` as described above and creates it when absent.
OutputDirState CheckOutputDir(const fs::path& dir, const OutputDirOptions& options);

// True when `inner` equals `outer` or lies inside it, after resolving ".",
// "..", and the symbolic links of the parts that exist.
bool IsSameOrInside(const fs::path& inner, const fs::path& outer);

}  // namespace u4d
