// Harness: the DICOM series reader (readers/dicom_reader.cpp through GDCM). The bytes are
// the files of a series, split at each line "@next.dcm" (a series needs two slices or more).
#include <string>

#include "core/error.h"
#include "fuzz/fuzz_files.h"
#include "readers/read_volume.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace isowall;
    constexpr std::string_view kMark = "\n@next.dcm\n";
    const auto dir = fuzz::scratch_folder("dicom") / "series";
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
    std::filesystem::create_directories(dir);
    std::string_view rest = fuzz::as_text(data, size);
    for (int i = 0; i < 8; ++i) {
        const std::size_t mark = rest.find(kMark);
        const char name[] = {'s', char('0' + i), '.', 'd', 'c', 'm', '\0'};
        fuzz::write_file(dir / name, rest.substr(0, mark));
        if (mark == std::string_view::npos) break;
        rest = rest.substr(mark + kMark.size());
    }
    try {
        fuzz::check_volume(formats::read_volume(dir.string(), std::nullopt));
    } catch (const InputError&) {
    }
    return 0;
}
