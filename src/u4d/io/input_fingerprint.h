// The fingerprint of a capture's inputs, kept in a 4D scene as inputs.json
// (io/layout.h) so that a resumed run can tell whether the capture changed
// since the run that wrote the scene (pipeline.h "Resume"):
//
//   {"format": "u4d-inputs",
//    "files": {"calibration.json": "c:5f0e3a8d2b417c69",
//              "images/cam00/000000.png": "m:48213:1764691200123456789", ...}}
//
// Keys are paths relative to the capture root ('/'-separated). What the
// capture describes is hashed by content ("c:" and a 64-bit FNV-1a in hex):
// capture.json, calibration.json and every file under masks/, poses2d/ and
// poses3d/. The frames (image files or videos, as capture.json names them)
// and the clean plates under background/ are recorded by size and
// modification time ("m:<bytes>:<ns>"), since hashing them would read the
// whole capture; rewriting a frame with other pixels changes its time. A
// frame that does not exist is "absent" (the frame reader names it when
// read). Ground truth (gt/) is no input: eval.json is recomputed on every run.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/io/capture.h"
#include "u4d/util/file.h"

namespace u4d {

struct InputFingerprint {
  std::map<std::string, std::string> files;  // relative path -> "c:<hash>" | "m:<size>:<ns>"
};

// Reads `capture`'s inputs as described above. Throws u4d::Error naming a
// file that exists but cannot be read.
InputFingerprint FingerprintCapture(const Capture& capture);

nlohmann::json FingerprintToJson(const InputFingerprint& fingerprint);
// Throws u4d::Error naming `context` when `json` is not a u4d-inputs object.
InputFingerprint FingerprintFromJson(const nlohmann::json& json, const std::string& context);

// The paths whose entry differs between `before` and `now` (changed, added
// or removed), sorted; empty when the inputs are the same.
std::vector<std::string> ChangedInputs(const InputFingerprint& before, const InputFingerprint& now);

// "c:" and the 64-bit FNV-1a hash of the file's bytes, in hex.
std::string HashFileContent(const fs::path& path);

}  // namespace u4d
