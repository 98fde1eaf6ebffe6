#pragma once
// The checks every command-line number goes through (the rule of core/number.h), and the
// check of a command's output files before any work.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/number.h"

namespace isowall {

// A CLI11 transform: the whole value must be a finite number in `range`, else CLI11 reports
// "OPTION: expected a number in [lo, hi], got "TEXT"". CLI::PositiveNumber and its kin let "nan"
// and "inf" through, and CLI11 reads an unsigned "-5" as 2^64 - 5 and "010" as octal 8, so an
// integer's text is rewritten in plain decimal for CLI11 to convert.
CLI::Validator number_in(const NumberRange& range);

// An output file and the option that names it.
struct OutputPath {
    std::string option;
    std::filesystem::path path;
};

// InputError(path, option, ...) for the first output that cannot be written (core/
// output_files.h: output_problem) or that another output of the same command names too.
void check_outputs(const std::vector<OutputPath>& outputs);

}  // namespace isowall
