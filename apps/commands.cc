#include "apps/commands.h"

namespace u4d::apps {

// One factory per apps/<name>_command.cc.
Command MakeInfoCommand();

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      MakeInfoCommand(),
  };
  return commands;
}

}  // namespace u4d::apps
