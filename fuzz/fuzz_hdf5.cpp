// Harness: the HDF5 reader (readers/hdf5_reader.cpp through libhdf5). The bytes are an
// HDF5 file, read as its only dataset.
#include "fuzz/fuzz_files.h"
#include "readers/read_volume.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    isowall::fuzz::read_as_file("hdf5", "in.h5", data, size, [](const std::string& path) {
        return isowall::formats::read_volume(path, std::nullopt);
    });
    return 0;
}
