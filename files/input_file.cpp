#include "files/input_file.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include "core/error.h"

namespace isowall {

std::string read_input_file(const std::filesystem::path& path, const std::string& field,
                            std::size_t max_bytes) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    const std::string where = path.string();
    if (!fs::exists(st)) throw InputError(where, field, "no such file");
    if (fs::is_directory(st)) throw InputError(where, field, "is a folder; expected a file");
    if (!fs::is_regular_file(st))
        throw InputError(where, field, "is not a regular file (a device, pipe or socket)");
    const auto size = fs::file_size(path, ec);
    if (!ec && size > max_bytes)
        throw InputError(
            where, field,
            "is " + std::to_string(size) + " bytes; expected at most " + std::to_string(max_bytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where, field, "cannot be opened");
    std::string text;
    text.resize(max_bytes + 1);  // one more, to tell a file that grew past the limit
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    if (in.bad()) throw InputError(where, field, "cannot be read");
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
        throw InputError(where, field, "expected at most " + std::to_string(max_bytes) + " bytes");
    return text;
}

}  // namespace isowall
