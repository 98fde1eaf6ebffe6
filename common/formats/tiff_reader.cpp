// Stacks of TIFF slices through OpenImageIO, which decodes every TIFF compression and sample
// layout (strips, tiles, planar, 12-bit packing) and hands back one slice in the type we ask.
// What we add: the slices in order (pages of one file, or files of a folder in natural name
// order), the check that every slice has one size and type before the stack is allocated, and
// the spacing ImageJ writes (its description's spacing= for z, the resolution tags for x and y).
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/core/error.h"
#include "common/core/number.h"
#include "common/formats/readers.h"
#include "common/formats/voxel_ops.h"
#include "common/volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

using Input = std::unique_ptr<OIIO::ImageInput>;

// What every slice must share.
struct Slice {
    int width = 0, height = 0;
    VoxelType type = VoxelType::u8;
    bool operator==(const Slice&) const = default;
};

std::string describe(const Slice& s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height) + " " +
           std::string(type_name(s.type));
}

std::optional<VoxelType> voxel_type_of(OIIO::TypeDesc t) {
    switch (t.basetype) {
        case OIIO::TypeDesc::UINT8:
            return VoxelType::u8;
        case OIIO::TypeDesc::INT8:
            return VoxelType::i8;
        case OIIO::TypeDesc::UINT16:
            return VoxelType::u16;
        case OIIO::TypeDesc::INT16:
            return VoxelType::i16;
        case OIIO::TypeDesc::UINT32:
            return VoxelType::u32;
        case OIIO::TypeDesc::INT32:
            return VoxelType::i32;
        case OIIO::TypeDesc::FLOAT:
            return VoxelType::f32;
        case OIIO::TypeDesc::DOUBLE:
            return VoxelType::f64;
        default:
            return std::nullopt;
    }
}

OIIO::TypeDesc type_desc(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return OIIO::TypeDesc::UINT8;
        case VoxelType::i8:
            return OIIO::TypeDesc::INT8;
        case VoxelType::u16:
            return OIIO::TypeDesc::UINT16;
        case VoxelType::i16:
            return OIIO::TypeDesc::INT16;
        case VoxelType::u32:
            return OIIO::TypeDesc::UINT32;
        case VoxelType::i32:
            return OIIO::TypeDesc::INT32;
        case VoxelType::f32:
            return OIIO::TypeDesc::FLOAT;
        case VoxelType::f64:
            return OIIO::TypeDesc::DOUBLE;
    }
    return OIIO::TypeDesc::UINT8;
}

// The slice a page holds: one channel, one plane, one of our types.
Slice slice_of(const OIIO::ImageSpec& spec, const std::string& where, const std::string& field) {
    if (spec.nchannels != 1)
        throw InputError(where, field,
                         std::to_string(spec.nchannels) +
                             " channels (colour or alpha); isowall reads one-channel slices");
    if (spec.depth != 1)
        throw InputError(
            where, field,
            "a volume TIFF of depth " + std::to_string(spec.depth) + "; isowall reads 2-D slices");
    const auto type = voxel_type_of(spec.format);
    if (!type)
        throw InputError(where, field,
                         std::string(spec.format.c_str()) +
                             " samples; isowall reads 8, 16 and 32-bit integers and floats");
    return {spec.width, spec.height, *type};
}

Input open_tiff(const fs::path& file, const std::string& where) {
    check_regular_file(file, where, "file");
    Input in = OIIO::ImageInput::open(file.string());
    if (!in) throw InputError(where, "file", "OpenImageIO cannot read it: " + OIIO::geterror());
    if (std::string_view(in->format_name()) != "tiff")
        throw InputError(
            where, "file",
            std::string("not a TIFF (OpenImageIO reads it as ") + in->format_name() + ")");
    return in;
}

int page_count(OIIO::ImageInput& in) {
    int n = 0;
    while (in.seek_subimage(n, 0)) ++n;
    in.geterror();  // seeking past the last page may leave a message we do not want
    return n;
}

// Names with their runs of digits compared as numbers: s2 before s10, s02 beside s2.
bool natural_less(const std::string& a, const std::string& b) {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        if (std::isdigit((unsigned char)a[i]) && std::isdigit((unsigned char)b[j])) {
            auto run = [](const std::string& s, std::size_t& k) {
                while (k < s.size() && s[k] == '0') ++k;  // leading zeros do not count
                const std::size_t from = k;
                while (k < s.size() && std::isdigit((unsigned char)s[k])) ++k;
                return std::string_view(s).substr(from, k - from);
            };
            const std::string_view x = run(a, i), y = run(b, j);
            if (x.size() != y.size()) return x.size() < y.size();
            if (x != y) return x < y;
        } else {
            if (a[i] != b[j]) return (unsigned char)a[i] < (unsigned char)b[j];
            ++i, ++j;
        }
    }
    if ((a.size() - i) != (b.size() - j)) return a.size() - i < b.size() - j;
    return a < b;  // equal but for leading zeros: any fixed order
}

bool is_tiff_name(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".tif" || ext == ".tiff";
}

// The folder's .tif/.tiff files (hidden ones left out), in natural name order.
std::vector<fs::path> slice_files(const fs::path& dir) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (e.is_regular_file() && !name.starts_with(".") && is_tiff_name(e.path()))
            files.push_back(e.path());
    }
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
        return natural_less(a.filename().string(), b.filename().string());
    });
    return files;
}

// The value of `key=` on its own line of an ImageJ description, or empty.
std::string imagej_value(std::string_view description, std::string_view key) {
    std::size_t at = 0;
    while (at < description.size()) {
        std::size_t end = description.find('\n', at);
        if (end == std::string_view::npos) end = description.size();
        const std::string_view line = description.substr(at, end - at);
        if (line.size() > key.size() && line.starts_with(key) && line[key.size()] == '=')
            return std::string(line.substr(key.size() + 1));
        at = end + 1;
    }
    return {};
}

bool is_imagej(const OIIO::ImageSpec& spec) {
    return std::string(spec.get_string_attribute("ImageDescription")).starts_with("ImageJ=");
}

// ImageJ's spacing: z from its description's spacing=, x and y from the resolution tags
// (pixels per unit); the unit from the description, else ResolutionUnit. Otherwise 1 1 1.
glm::vec3 stack_spacing(const OIIO::ImageSpec& spec, std::vector<VolumeFact>& facts) {
    const std::string text = spec.get_string_attribute("ImageDescription");
    const auto z = is_imagej(spec) ? parse_number(imagej_value(text, "spacing")) : std::nullopt;
    const float xres = spec.get_float_attribute("XResolution", 0);
    const float yres = spec.get_float_attribute("YResolution", 0);
    if (!z || !(xres > 0) || !(yres > 0)) {
        facts.push_back({"spacing from", "none in the file (1 1 1)"});
        return glm::vec3(1.0f);
    }
    std::string unit = imagej_value(text, "unit");
    if (unit.empty()) unit = spec.get_string_attribute("ResolutionUnit", "none");
    facts.push_back({"spacing from",
                     "ImageJ description (spacing=) and X/YResolution, unit " + clip(unit, 20)});
    return {1.0f / xres, 1.0f / yres, float(*z)};
}

// An ImageJ hyperstack keeps its channels and time points as pages too: read as slices they
// would interleave silently.
void check_imagej_stack(const OIIO::ImageSpec& spec, int pages, const std::string& where) {
    if (!is_imagej(spec)) return;
    const std::string text = spec.get_string_attribute("ImageDescription");
    for (const char* key : {"channels", "frames"}) {
        const auto n = parse_number(imagej_value(text, key));
        if (n && *n > 1)
            throw InputError(where, "ImageDescription",
                             "an ImageJ hyperstack of " + imagej_value(text, key) + " " + key +
                                 "; isowall reads one channel at one time point");
    }
    const auto images = parse_number(imagej_value(text, "images"));
    if (images && *images > pages)
        throw InputError(where, "ImageDescription",
                         "ImageJ says " + imagej_value(text, "images") + " images, the file has " +
                             std::to_string(pages) +
                             " pages (ImageJ writes stacks past 4 GiB as raw data after one "
                             "page, which is not TIFF)");
}

void check_count(std::size_t slices, const std::string& where, const std::string& field) {
    if (slices < 2)
        throw InputError(where, field,
                         std::to_string(slices) + " slice(s); a volume needs at least 2");
}

Decoded allocate_stack(const Slice& first, std::uint64_t slices, const std::string& where,
                       const std::string& field) {
    Decoded d;
    d.type = first.type;
    const std::uint64_t sizes[3] = {std::uint64_t(first.width), std::uint64_t(first.height),
                                    slices};
    d.dims = checked_dims(where, field, sizes, d.type);
    d.bytes = allocate_voxels(voxel_bytes(d.dims, d.type), where, field);
    return d;
}

void read_slice(OIIO::ImageInput& in, int page, int z, Decoded& d, const std::string& where) {
    const std::size_t slice_bytes = std::size_t(d.dims.x) * d.dims.y * voxel_size(d.type);
    if (!in.read_image(page, 0, 0, 1, type_desc(d.type), d.bytes.data() + slice_bytes * z))
        throw InputError(where, "page " + std::to_string(page),
                         "OpenImageIO cannot decode it: " + in.geterror());
}

Decoded read_pages(const fs::path& file, const std::string& where) {
    Input in = open_tiff(file, where);
    const int pages = page_count(*in);
    const OIIO::ImageSpec spec0 = in->spec(0, 0);
    check_imagej_stack(spec0, pages, where);
    check_count(std::size_t(pages), where, "pages");
    const Slice first = slice_of(spec0, where, "page 0");
    for (int p = 1; p < pages; ++p) {
        const std::string field = "page " + std::to_string(p);
        const Slice s = slice_of(in->spec(p, 0), where, field);
        if (!(s == first))
            throw InputError(
                where, field,
                describe(s) + ", but page 0 is " + describe(first) + "; every slice must match");
    }
    Decoded d = allocate_stack(first, std::uint64_t(pages), where, "pages");
    for (int p = 0; p < pages; ++p) read_slice(*in, p, p, d, where);
    d.spacing = stack_spacing(spec0, d.facts);
    d.files = {file};
    return d;
}

// The folder's slices, each opened and checked before the stack is allocated (a bad slice costs
// no allocation), then each opened again to read: a folder may hold more slices than a process
// may keep open.
Decoded read_folder(const fs::path& dir, const std::string& where) {
    const std::vector<fs::path> files = slice_files(dir);
    check_count(files.size(), where, "slices");
    Slice first;
    OIIO::ImageSpec spec0;
    for (const fs::path& f : files) {
        const std::string at = f.string();
        const Input in = open_tiff(f, at);
        if (page_count(*in) != 1)
            throw InputError(at, "pages", "a slice of a folder must be a single page");
        const Slice s = slice_of(in->spec(0, 0), at, "slice");
        if (f == files.front()) {
            first = s;
            spec0 = in->spec(0, 0);
        } else if (!(s == first)) {
            throw InputError(at, "size",
                             describe(s) + ", but the first slice (" +
                                 files.front().filename().string() + ") is " + describe(first) +
                                 "; every slice must match");
        }
    }
    Decoded d = allocate_stack(first, files.size(), where, "slices");
    for (std::size_t z = 0; z < files.size(); ++z)
        read_slice(*open_tiff(files[z], files[z].string()), 0, int(z), d, files[z].string());
    d.spacing = stack_spacing(spec0, d.facts);
    d.files = files;
    return d;
}

}  // namespace

Volume read_tiff_stack(const fs::path& path) {
    const std::string where = path.string();
    std::error_code ec;
    Decoded d = fs::is_directory(path, ec) ? read_folder(path, where) : read_pages(path, where);
    d.format = "TIFF";
    d.facts.push_back({"slices", std::to_string(d.dims.z) +
                                     (d.files.size() > 1 ? " files" : " pages of one file")});
    return finish_volume(std::move(d), where, "scaling");
}

}  // namespace isowall::formats
