#pragma once
// The master's console (`--script -`): commands typed on its terminal, one per line. A typo is
// reported and skipped (unlike a script file, where a bad line stops the job before any frame).
#include <functional>
#include <string>

#include "wall_spec/script.h"

namespace isowall {

// Runs each line read from `fd` through `execute` (which returns false for quit) until quit or
// the end of input; InputError from a line or from execute is printed and the console goes on.
// While no line is waiting, `idle` runs every few tens of milliseconds (the master takes the
// tiles' messages and keeps the wall alive while the operator types).
void run_console(int fd,
                 const std::function<bool(const ScriptCommand&, const std::string& where)>& execute,
                 const std::function<void()>& idle);

}  // namespace isowall
