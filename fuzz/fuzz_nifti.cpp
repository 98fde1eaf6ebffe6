// Harness: the NIfTI reader (common/formats/nifti_reader.cpp through niftilib). The bytes are a
// .nii file.
#include "common/core/error.h"
#include "common/formats/read_volume.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    const auto path = fuzz::scratch_folder("nifti") / "in.nii";
    fuzz::write_file(path, fuzz::as_text(data, size));
    try {
        fuzz::check_volume(formats::read_volume(path.string(), std::nullopt));
    } catch (const InputError&) {
    }
    return 0;
}
