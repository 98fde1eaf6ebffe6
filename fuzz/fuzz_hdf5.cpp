// Harness: the HDF5 reader (common/formats/hdf5_reader.cpp through libhdf5). The bytes are an
// HDF5 file, read as its only dataset.
#include "common/core/error.h"
#include "common/formats/read_volume.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    const auto path = fuzz::scratch_folder("hdf5") / "in.h5";
    fuzz::write_file(path, fuzz::as_text(data, size));
    try {
        fuzz::check_volume(formats::read_volume(path.string(), std::nullopt));
    } catch (const InputError&) {
    }
    return 0;
}
