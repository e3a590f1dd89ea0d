// The subcommand table of `u4d`. Each command lives in its own file
// apps/<name>_command.cc and registers here; options are bound to a struct
// owned by that file, so there is no global mutable configuration.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace u4d::apps {

struct Command {
  std::string name;
  std::string help;
  std::function<void(CLI::App&)> setup;  // declares options
  std::function<int()> run;              // runs after parsing; returns the exit code
};

const std::vector<Command>& Commands();

}  // namespace u4d::apps
