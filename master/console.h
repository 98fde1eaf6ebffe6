#pragma once
// The master's console (`--script -`): commands typed on its terminal, one per line. A typo is
// reported and skipped (unlike a script file, where a bad line stops the job before any frame).
#include <functional>
#include <istream>
#include <string>

#include "common/wall/script.h"

namespace isowall {

// Runs each line's command through `execute` (which returns false for quit) until quit or the
// end of input; InputError from a line or from execute is printed and the console goes on.
void run_console(
    std::istream& in,
    const std::function<bool(const ScriptCommand&, const std::string& where)>& execute);

}  // namespace isowall
