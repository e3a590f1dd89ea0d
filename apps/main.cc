// The `u4d` command: a table of subcommands (apps/commands.h).
#include <cstdio>
#include <exception>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/util/check.h"

namespace {

int RunCli(int argc, char** argv) {
  CLI::App app{"U4D: unsupervised 4D dynamic scene understanding from multi-view video"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "print detail");
  for (const u4d::apps::Command& command : u4d::apps::Commands()) {
    CLI::App* sub = app.add_subcommand(command.name, command.help);
    command.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  for (const u4d::apps::Command& command : u4d::apps::Commands()) {
    if (!app.got_subcommand(command.name)) continue;
    // Bad input is a u4d::Error (exit 1). Anything else escaping a command is
    // a bug in U4D; the last-resort handlers say so and exit 2.
    try {
      return command.run();
    } catch (const u4d::Error& e) {
      std::fprintf(stderr, "u4d %s: error: %s\n", command.name.c_str(), e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "u4d %s: internal error: %s\n", command.name.c_str(), e.what());
      return 2;
    } catch (...) {
      std::fprintf(stderr, "u4d %s: internal error: unknown exception\n", command.name.c_str());
      return 2;
    }
  }
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Setting up the command table throws only on a bug in U4D (say, two
  // commands declaring the same option): exit 2 as for a command's bug.
  try {
    return RunCli(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "u4d: internal error: %s\n", e.what());
    return 2;
  } catch (...) {
    std::fprintf(stderr, "u4d: internal error: unknown exception\n");
    return 2;
  }
}
