#include "apps/commands.h"

namespace u4d::apps {

// One factory per apps/<name>_command.cc.
Command MakeInfoCommand();
Command MakeEvalCommand();
Command MakeImportCommand();
Command MakeSynthCommand();
Command MakeDemoCommand();

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      MakeInfoCommand(),  MakeEvalCommand(), MakeImportCommand(),
      MakeSynthCommand(), MakeDemoCommand(),
  };
  return commands;
}

}  // namespace u4d::apps
