// File helpers with the project's error and durability rules:
//  - every read failure throws u4d::Error naming the path and the problem;
//  - every write goes to "<path>.tmp-<pid>" first and is renamed into place,
//    so a crash never leaves a half-written file under the final name.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace u4d {

namespace fs = std::filesystem;

// Throws if `path` does not exist or is not a regular file.
void CheckFileExists(const fs::path& path, const std::string& what = "file");
// Throws if `path` does not exist or is not a directory.
void CheckDirExists(const fs::path& path, const std::string& what = "directory");

// fs::create_directories with a u4d::Error naming the path on failure.
void CreateDirectories(const fs::path& dir);

// The non-negative integer spelled by `name` (decimal digits only, fitting an
// int), e.g. an object id folder "7"; nullopt for anything else ("abc",
// "-1", "7.tmp", ""), so stray entries in an output folder can be skipped.
std::optional<int> ParseIndexName(const std::string& name);

std::string ReadTextFile(const fs::path& path);

// Parses JSON; a syntax error or a number overflow (1e999) is reported with
// the file name and position (util/json_checked.h has the checked accessors).
nlohmann::json ReadJsonFile(const fs::path& path);

// Writes by calling `write_to(tmp_path)`, then renames tmp onto `path`.
// Parent directories are created. If write_to throws, the temporary file is
// removed and the previous content of `path` (if any) is untouched.
void WriteAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to);

// True for the name of WriteAtomically's temporary file ("<stem>.tmp-<pid>"
// followed by the extension), which a killed process leaves behind.
bool IsAtomicWriteTemporary(const fs::path& path);

void WriteTextFileAtomic(const fs::path& path, const std::string& text);
void WriteJsonFileAtomic(const fs::path& path, const nlohmann::json& json, int indent = 1);

// A JSON value that must be a finite number / an integer; errors name
// `context` (usually the file) and `what` (the field).
double JsonNumber(const nlohmann::json& v, const std::string& context, const std::string& what);
int64_t JsonInteger(const nlohmann::json& v, const std::string& context, const std::string& what);

// Typed access to a JSON field with an error naming `context` (usually the
// file) and the key when the field is missing or has the wrong type; the same
// as JsonRequired (util/json_checked.h), numbers range-checked.
template <typename T>
T JsonGet(const nlohmann::json& j, const std::string& key, const std::string& context);

}  // namespace u4d

#include "u4d/util/file_inl.h"
