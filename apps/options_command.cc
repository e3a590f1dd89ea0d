// `u4d options`: every option of `u4d run` with its key, type, default and
// help, from the options registry (u4d/util/options.h): the text of
// docs/options.md, or the defaults as the JSON of params.json.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/pipeline/run_flags.h"

namespace u4d::apps {

Command MakeOptionsCommand() {
  auto json = std::make_shared<bool>(false);
  auto markdown = std::make_shared<bool>(false);
  return {"options", "list every option of `u4d run` (docs/options.md) or its defaults as JSON",
          [=](CLI::App& app) {
            app.add_flag("--json", *json,
                         "print the default options as JSON (the layout of params.json and "
                         "--config)");
            app.add_flag("--markdown", *markdown, "print docs/options.md (the default)");
          },
          [=] {
            if (*json)
              fmt::print("{}\n", RunOptions().ToJson().dump(2));
            else
              fmt::print("{}", RunOptionsMarkdown());
            return 0;
          }};
}

}  // namespace u4d::apps
