// Harness: the TIFF stack reader (common/formats/tiff_reader.cpp through OpenImageIO). The
// bytes are a multi-page TIFF file.
#include "common/core/error.h"
#include "common/formats/read_volume.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    const auto path = fuzz::scratch_folder("tiff") / "in.tif";
    fuzz::write_file(path, fuzz::as_text(data, size));
    try {
        fuzz::check_volume(formats::read_volume(path.string(), std::nullopt));
    } catch (const InputError&) {
    }
    return 0;
}
