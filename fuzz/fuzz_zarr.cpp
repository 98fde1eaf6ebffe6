// Harness: the Zarr reader (readers/zarr_reader.cpp) on another tool's store: the metadata, the
// chunk keys, the codecs' framing and the chunks put in place. The bytes are a store in one text:
// everything before the first line "@KEY" is the array's metadata (Zarr v3's zarr.json where it
// says "node_type", else v2's .zarray), and each "@KEY" line starts the chunk file KEY (digits,
// '.' and '/', after an optional v3 "c/" or "c.") that runs to the next such line. A v3 chunk
// may be a shard of inner chunks under an index. A store that loads passes fuzz_files.h's
// check_volume and names its metadata file first among its files.
//
// Blosc is left out (a .zarray naming it is skipped): isowall decodes Blosc chunks in a child
// process (readers/read_volume.cpp), as GDCM and libhdf5, so a crash of c-blosc on a damaged
// chunk is one line; this harness covers isowall's own code and zstd, zlib and lz4 in-process.
#include <fstream>
#include <string>
#include <string_view>

#include "core/error.h"
#include "fuzz/fuzz_files.h"
#include "readers/zarr_reader.h"

namespace {

// A chunk key the store may hold: indices and separators only (after v3's "c/" or "c."), no "..",
// no leading '/'.
bool plain_key(std::string_view key) {
    if (key.starts_with("c/") || key.starts_with("c.")) key.remove_prefix(2);
    if (key.empty() || key.size() > 64 || key.front() == '/' || key.back() == '/' ||
        key.find("..") != key.npos || key.find("//") != key.npos)
        return false;
    for (const char c : key)
        if (!(c >= '0' && c <= '9') && c != '.' && c != '/') return false;
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    namespace fs = std::filesystem;
    const fs::path dir = fuzz::scratch_folder("zarr") / "store";
    std::error_code ignored;  // no chunk of the last input may answer for this one
    fs::remove_all(dir, ignored);
    fs::create_directories(dir);

    const std::string_view text = fuzz::as_text(data, size);
    std::size_t at = text.find("\n@");
    const std::string_view meta = text.substr(0, at);
    if (meta.find("blosc") != meta.npos) return 0;
    const fs::path meta_file =
        dir / (meta.find("node_type") != meta.npos ? "zarr.json" : ".zarray");
    fuzz::write_file(meta_file, meta);
    while (at != text.npos) {
        const std::size_t key_end = text.find('\n', at + 2);
        if (key_end == text.npos) break;
        const std::string_view key = text.substr(at + 2, key_end - at - 2);
        at = text.find("\n@", key_end);
        const std::string_view body =
            text.substr(key_end + 1, at == text.npos ? at : at - key_end - 1);
        if (!plain_key(key)) continue;
        // A key that names a folder another key made (or the reverse) is not written: the store
        // holds what a file system can.
        const fs::path file = dir / std::string(key);
        fs::create_directories(file.parent_path(), ignored);
        std::ofstream(file, std::ios::binary | std::ios::trunc)
            .write(body.data(), static_cast<std::streamsize>(body.size()));
    }
    try {
        const Volume v = formats::read_zarr(dir);
        fuzz::check_volume(v);
        fuzz::check(!v.files().empty() && v.files().front() == meta_file,
                    "the metadata file is the first of the volume's files");
    } catch (const InputError&) {
    }
    return 0;
}
