// Harness: the NIfTI reader (readers/nifti_reader.cpp through niftilib). The bytes are a
// .nii file.
#include "fuzz/fuzz_files.h"
#include "readers/read_volume.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    isowall::fuzz::read_as_file("nifti", "in.nii", data, size, [](const std::string& path) {
        return isowall::formats::read_volume(path, std::nullopt);
    });
    return 0;
}
