#include "u4d/io/output_dir.h"

#include <fstream>

#include <fmt/ranges.h>

#include <unistd.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

fs::path Resolved(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  fs::path canon = fs::weakly_canonical(abs, ec);
  return (ec ? abs.lexically_normal() : canon.lexically_normal());
}

// The path without a trailing separator, so "a/b/" and "a/b" compare equal.
fs::path Trimmed(const fs::path& p) {
  fs::path out;
  for (const fs::path& part : p)
    if (!part.empty()) out /= part;
  return out;
}

bool IsEmptyDir(const fs::path& dir, const std::string& what) {
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  U4D_CHECK(!ec, "{}: cannot list {}: {}", what, dir.string(), ec.message());
  return it == fs::directory_iterator();
}

void ProbeWritable(const fs::path& dir, const std::string& what) {
  const fs::path probe = dir / (".u4d-write-probe-" + std::to_string(::getpid()));
  {
    std::ofstream out(probe);
    out << "probe";
    out.close();
    U4D_CHECK(out.good(), "{}: {} is not writable", what, dir.string());
  }
  std::error_code ec;
  fs::remove(probe, ec);
}

}  // namespace

void OutputDirOptions::Check() const {
  U4D_CHECK(!flag.empty() && !command.empty(), "OutputDirOptions: flag and command must be set");
}

bool IsSameOrInside(const fs::path& inner, const fs::path& outer) {
  const fs::path in = Trimmed(Resolved(inner)), out = Trimmed(Resolved(outer));
  auto i = in.begin();
  for (auto o = out.begin(); o != out.end(); ++o, ++i)
    if (i == in.end() || *i != *o) return false;
  return true;
}

OutputDirState CheckOutputDir(const fs::path& dir, const OutputDirOptions& o) {
  o.Check();
  const std::string what = fmt::format("{} {} {}", o.command, o.flag, dir.string());
  U4D_CHECK(!dir.empty(), "{} {}: the output folder must not be empty", o.command, o.flag);
  for (const fs::path& input : o.inputs)
    U4D_CHECK(!IsSameOrInside(dir, input),
              "{}: the output folder is the input {} or inside it; write elsewhere so the "
              "input stays untouched",
              what, input.string());
  for (const fs::path& input : o.input_roots)
    U4D_CHECK(!IsSameOrInside(dir, input) || !IsSameOrInside(input, dir),
              "{}: the output folder is the input {}; write elsewhere (a subfolder is fine) so "
              "the input stays untouched",
              what, input.string());
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  U4D_CHECK(!ec || st.type() == fs::file_type::not_found, "{}: cannot access the folder: {}", what,
            ec.message());
  OutputDirState state = OutputDirState::kCreated;
  if (fs::exists(st)) {
    U4D_CHECK(fs::is_directory(st), "{}: exists and is not a directory", what);
    if (IsEmptyDir(dir, what)) {
      state = OutputDirState::kEmpty;
    } else {
      bool previous = false;
      for (const std::string& m : o.markers) previous = previous || fs::exists(dir / m, ec);
      if (previous) {
        state = OutputDirState::kPreviousOutput;
      } else {
        U4D_CHECK(o.force,
                  "{}: the folder is not empty and is not a previous output of {} (no {}); "
                  "choose an empty or new folder{}",
                  what, o.command, fmt::join(o.markers, " or "),
                  o.force_flag.empty() ? "" : " or pass " + o.force_flag);
        state = OutputDirState::kForced;
      }
    }
  } else {
    fs::create_directories(dir, ec);
    U4D_CHECK(!ec, "{}: cannot create the folder: {}", what, ec.message());
  }
  ProbeWritable(dir, what);
  return state;
}

}  // namespace u4d
