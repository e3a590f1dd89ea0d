// The fields of the options structs of unsupervised initial masks (init.h), each declared once
// (name, help; the default is the struct's initialiser): params.json,
// `u4d run --config` / `--set` and docs/options.md come from these
// (util/options.h). Check() stays with each struct.
#pragma once

#include "u4d/init/init.h"
#include "u4d/util/options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, BackgroundOptions* o);
void DeclareOptions(OptionRegistry& r, ForegroundOptions* o);
void DeclareOptions(OptionRegistry& r, CrossViewOptions* o);
void DeclareOptions(OptionRegistry& r, PeopleOptions* o);
void DeclareOptions(OptionRegistry& r, StillOptions* o);
void DeclareOptions(OptionRegistry& r, GroundOptions* o);
void DeclareOptions(OptionRegistry& r, InitOptions* o);
void DeclareOptions(OptionRegistry& r, ChromaKeyOptions* o);

}  // namespace u4d
