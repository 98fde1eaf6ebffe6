// Harness: the MetaImage reader (readers/metaimage_reader.cpp), header parser and data
// together. Without a line "@data.raw" the bytes are in.mha (a LOCAL header with its data after
// it); with one, everything before it is in.mhd and everything after it data.raw beside it (for
// "ElementDataFile = data.raw" headers). A volume that loads passes fuzz_files.h's check_volume
// and names its header first among its files.
#include "core/error.h"
#include "fuzz/fuzz_files.h"
#include "readers/readers.h"

namespace {
constexpr std::string_view kDataMark = "\n@data.raw\n";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    namespace fs = std::filesystem;
    const fs::path& dir = fuzz::scratch_folder("metaimage");
    std::error_code ignored;  // no file of the last input may answer for this one
    for (const char* name : {"in.mha", "in.mhd", "data.raw"}) fs::remove(dir / name, ignored);

    const std::string_view text = fuzz::as_text(data, size);
    const std::size_t mark = text.find(kDataMark);
    const fs::path header = dir / (mark == std::string_view::npos ? "in.mha" : "in.mhd");
    fuzz::write_file(header, text.substr(0, mark));
    if (mark != std::string_view::npos)
        fuzz::write_file(dir / "data.raw", text.substr(mark + kDataMark.size()));
    try {
        const Volume v = formats::read_metaimage(header);
        fuzz::check_volume(v);
        fuzz::check(!v.files().empty() && v.files().front() == header,
                    "the header is the first of the volume's files");
    } catch (const InputError&) {
    }
    return 0;
}
