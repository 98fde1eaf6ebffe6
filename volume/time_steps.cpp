#include "volume/time_steps.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <optional>
#include <system_error>

#include "core/error.h"

namespace isowall {
namespace {

// The pattern cut at its conversion: the text before it, its zero-padded width (0: none), the
// text after it; nullopt when there is no conversion.
struct Conversion {
    std::string before, after;
    int width = 0;
};

std::optional<Conversion> conversion_of(std::string_view p) {
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p[i] != '%') continue;
        std::size_t j = i + 1;
        int width = 0;
        if (j < p.size() && p[j] == '0') {
            ++j;
            const std::size_t start = j;
            while (j < p.size() && p[j] >= '0' && p[j] <= '9') ++j;
            if (j == start || j - start > 2) continue;
            std::from_chars(p.data() + start, p.data() + j, width);
        }
        if (j < p.size() && p[j] == 'd')
            return Conversion{std::string(p.substr(0, i)), std::string(p.substr(j + 1)), width};
    }
    return std::nullopt;
}

std::string numbered(const Conversion& c, int n) {
    std::string digits = std::to_string(n);
    if (int(digits.size()) < c.width) digits.insert(0, std::size_t(c.width) - digits.size(), '0');
    return c.before + digits + c.after;
}

}  // namespace

bool is_series_pattern(std::string_view path) {
    return conversion_of(path).has_value();
}

TimeSeries find_series(const std::string& pattern, const std::string& option) {
    const std::optional<Conversion> c = conversion_of(pattern);
    if (!c) throw InputError(pattern, option, "expected a pattern with %d or %0Nd");
    if (is_series_pattern(c->after) || is_series_pattern(c->before))
        throw InputError(pattern, option, "expected one %d or %0Nd, found more");
    const std::filesystem::path before(c->before);
    if (c->after.find('/') != std::string::npos)
        throw InputError(pattern, option, "the number must be in the file's name, not a folder's");
    const std::filesystem::path folder =
        before.has_parent_path() || c->before.ends_with('/') ? before.parent_path() : ".";
    const std::string name_before =
        c->before.ends_with('/') ? std::string() : before.filename().string();
    std::map<int, std::filesystem::path> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.size() <= name_before.size() + c->after.size() || !name.starts_with(name_before) ||
            !name.ends_with(c->after))
            continue;
        const std::string_view digits(name.data() + name_before.size(),
                                      name.size() - name_before.size() - c->after.size());
        int n = 0;
        const auto [end, err] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
        if (err != std::errc{} || end != digits.data() + digits.size() || n < 0) continue;
        if (found.size() >= kMaxTimeSteps)
            throw InputError(pattern, option,
                             "more than " + std::to_string(kMaxTimeSteps) + " time steps");
        found.emplace(n, entry.path());
    }
    if (ec) throw InputError(folder.string(), option, "cannot list the folder: " + ec.message());
    if (found.empty()) throw InputError(pattern, option, "no file matches the pattern");
    TimeSeries s{pattern, found.begin()->first, {}};
    const int last = found.rbegin()->first;
    for (int n = s.first; n <= last; ++n) {
        const auto it = found.find(n);
        if (it == found.end())
            throw InputError(numbered(*c, n), option,
                             "time step " + std::to_string(n - s.first) + " is missing (files " +
                                 std::to_string(s.first) + " to " + std::to_string(last) +
                                 " found)");
        s.steps.push_back(it->second);
    }
    return s;
}

}  // namespace isowall
