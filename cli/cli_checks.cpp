#include "cli/cli_checks.h"

#include <cstdio>
#include <system_error>

#include "core/error.h"
#include "files/output_files.h"

namespace isowall {

CLI::Validator number_in(const NumberRange& range) {
    return CLI::Validator(
        [range](std::string& text) {
            std::string problem = number_problem(text, range);
            if (!problem.empty()) return problem;
            if (range.integer) {
                char buf[32];
                std::snprintf(buf, sizeof(buf), "%.0f", *parse_number(text));
                text = buf;
            }
            return std::string();
        },
        range.describe());
}

namespace {

// Whether two output paths name one file: "a.png", "./a.png" and "x/../a.png" do. (Absolute
// first: weakly_canonical leaves a relative path with no existing prefix relative.)
bool same_file_name(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ec;
    const auto full = [&](const std::filesystem::path& p) {
        return std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
    };
    return full(a) == full(b);
}

}  // namespace

void check_outputs(const std::vector<OutputPath>& outputs) {
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        check_output(outputs[i].path, outputs[i].option);
        for (std::size_t k = 0; k < i; ++k)
            if (same_file_name(outputs[k].path, outputs[i].path))
                throw InputError(
                    outputs[i].path.string(), outputs[i].option,
                    "is also the file of " + outputs[k].option + "; expected a file of its own");
    }
}

}  // namespace isowall
