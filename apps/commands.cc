#include "apps/commands.h"

namespace u4d::apps {

// One factory per apps/<name>_command.cc.
Command MakeInfoCommand();
Command MakeEvalCommand();
Command MakeImportCommand();
Command MakeSynthCommand();
Command MakeDemoCommand();
Command MakeRunCommand();
Command MakeSceneFromGtCommand();
Command MakeViewCommand();
Command MakeExportViewerCommand();
Command MakeConsistencyCommand();
Command MakeOptionsCommand();

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      MakeInfoCommand(),        MakeEvalCommand(),    MakeImportCommand(),
      MakeSynthCommand(),       MakeRunCommand(),     MakeDemoCommand(),
      MakeSceneFromGtCommand(), MakeViewCommand(),    MakeExportViewerCommand(),
      MakeConsistencyCommand(), MakeOptionsCommand(),
  };
  return commands;
}

}  // namespace u4d::apps
