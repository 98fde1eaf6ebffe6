// Harness: the TIFF stack reader (readers/tiff_reader.cpp through OpenImageIO). The
// bytes are a multi-page TIFF file.
#include "fuzz/fuzz_files.h"
#include "readers/read_volume.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    isowall::fuzz::read_as_file("tiff", "in.tif", data, size, [](const std::string& path) {
        return isowall::formats::read_volume(path, std::nullopt);
    });
    return 0;
}
