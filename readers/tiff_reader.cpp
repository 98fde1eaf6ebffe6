// Stacks of TIFF slices through OpenImageIO, which decodes every TIFF compression and sample
// layout (strips, tiles, planar, 12-bit packing) and hands back one slice in the type we ask.
// What we add: the slices in order (pages of one file, or files of a folder in natural name
// order), the check that every slice has one size and type before the stack is allocated, and
// the spacing ImageJ writes (its description's spacing= for z, the resolution tags for x and y).
#include <algorithm>
#include <cctype>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/number.h"
#include "files/oiio_module.h"
#include "readers/plane_stack.h"
#include "readers/readers.h"
#include "readers/tiff_directories.h"
#include "readers/voxel_ops.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

// An image file open through the OpenImageIO module.
class Input {
  public:
    explicit Input(void* file) : file_(file) {}
    Input(const Input&) = delete;
    Input& operator=(const Input&) = delete;
    ~Input() { oiio::api().close_file(file_); }
    int page_count() const { return oiio::api().page_count(file_); }
    int directories = 0;  // whole ones in the file's chain (tiff_directories)
    oiio::PageInfo spec(int page) const {
        oiio::PageInfo info;
        oiio::api().page_info(file_, page, info);
        return info;
    }
    bool read(int page, oiio::Sample sample, void* out, std::string& error) const {
        return oiio::api().read_page(file_, page, sample, out, error);
    }

  private:
    void* file_;
};

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

// oiio::Sample lists VoxelType's types in VoxelType's order, then `other`.
static_assert(int(oiio::Sample::u8) == int(VoxelType::u8) &&
              int(oiio::Sample::i8) == int(VoxelType::i8) &&
              int(oiio::Sample::u16) == int(VoxelType::u16) &&
              int(oiio::Sample::i16) == int(VoxelType::i16) &&
              int(oiio::Sample::u32) == int(VoxelType::u32) &&
              int(oiio::Sample::i32) == int(VoxelType::i32) &&
              int(oiio::Sample::f32) == int(VoxelType::f32) &&
              int(oiio::Sample::f64) == int(VoxelType::f64));

std::optional<VoxelType> voxel_type_of(oiio::Sample t) {
    if (t == oiio::Sample::other) return std::nullopt;
    return static_cast<VoxelType>(static_cast<int>(t));
}

oiio::Sample sample_of(VoxelType t) {
    return static_cast<oiio::Sample>(static_cast<int>(t));
}

// The slice a page holds: one channel, one plane, one of our types.
Slice slice_of(const oiio::PageInfo& spec, const std::string& where, const std::string& field) {
    if (spec.channels != 1)
        throw InputError(where, field,
                         std::to_string(spec.channels) +
                             " channels (colour or alpha); isowall reads one-channel slices");
    if (spec.depth != 1)
        throw InputError(
            where, field,
            "a volume TIFF of depth " + std::to_string(spec.depth) + "; isowall reads 2-D slices");
    const auto type = voxel_type_of(spec.sample);
    if (!type)
        throw InputError(
            where, field,
            spec.format + " samples; isowall reads 8, 16 and 32-bit integers and floats");
    const std::uint64_t bytes = std::uint64_t(std::max(spec.width, 0)) *
                                std::uint64_t(std::max(spec.height, 0)) * voxel_size(*type);
    if (bytes > kMaxSliceBytes)
        throw InputError(where, field,
                         std::to_string(spec.width) + "x" + std::to_string(spec.height) + " " +
                             std::string(type_name(*type)) + " is " + std::to_string(bytes) +
                             " bytes; isowall reads slices of at most " +
                             std::to_string(kMaxSliceBytes >> 20) + " MiB");
    return {spec.width, spec.height, *type};
}

std::unique_ptr<Input> open_tiff(const fs::path& file, const std::string& where) {
    check_regular_file(file, where, "file");
    std::string format, error;
    void* handle = oiio::api().open_file(file.string(), format, error);
    if (!handle) throw InputError(where, "file", "OpenImageIO cannot read it: " + error);
    auto in = std::make_unique<Input>(handle);
    if (format != "tiff")
        throw InputError(where, "file", "not a TIFF (OpenImageIO reads it as " + format + ")");
    std::ifstream raw(file, std::ios::binary);
    std::error_code ec;
    const std::uint64_t size = fs::file_size(file, ec);
    const TiffDirectories dirs = tiff_directories(raw, ec ? 0 : size);
    if (!dirs.problem.empty()) throw InputError(where, "directories", dirs.problem);
    in->directories = dirs.pages;
    return in;
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

bool is_imagej(const oiio::PageInfo& spec) {
    return spec.description.starts_with("ImageJ=");
}

// ImageJ's spacing: z from its description's spacing=, x and y from the resolution tags
// (pixels per unit); the unit from the description, else ResolutionUnit. Otherwise 1 1 1.
glm::vec3 stack_spacing(const oiio::PageInfo& spec, std::vector<VolumeFact>& facts) {
    const std::string& text = spec.description;
    const auto z = is_imagej(spec) ? parse_number(imagej_value(text, "spacing")) : std::nullopt;
    const float xres = spec.x_resolution;
    const float yres = spec.y_resolution;
    if (!z || !(xres > 0) || !(yres > 0)) {
        facts.push_back({"spacing from", "none in the file (1 1 1)"});
        return glm::vec3(1.0f);
    }
    std::string unit = imagej_value(text, "unit");
    if (unit.empty()) unit = spec.resolution_unit.empty() ? "none" : spec.resolution_unit;
    facts.push_back({"spacing from",
                     "ImageJ description (spacing=) and X/YResolution, unit " + clip(unit, 20)});
    return {1.0f / xres, 1.0f / yres, float(*z)};
}

// An ImageJ hyperstack keeps its channels and time points as pages too: read as slices they
// would interleave silently.
void check_imagej_stack(const oiio::PageInfo& spec, int pages, const std::string& where) {
    if (!is_imagej(spec)) return;
    const std::string& text = spec.description;
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

// The stack's description once every slice has been checked (a bad slice costs no allocation).
Decoded describe_stack(const Slice& first, std::uint64_t slices, const std::string& where,
                       const std::string& field) {
    Decoded d;
    d.type = first.type;
    const std::uint64_t sizes[3] = {std::uint64_t(first.width), std::uint64_t(first.height),
                                    slices};
    d.dims = checked_dims(where, field, sizes, d.type);
    return d;
}

void read_slice(const Input& in, int page, std::byte* to, oiio::Sample sample,
                const std::string& where) {
    std::string error;
    if (!in.read(page, sample, to, error))
        throw InputError(where, "page " + std::to_string(page),
                         "OpenImageIO cannot decode it: " + error);
}

std::size_t slice_bytes(const Decoded& d) {
    return std::size_t(d.dims.x) * d.dims.y * voxel_size(d.type);
}

PlaneStack read_pages(const fs::path& file, const std::string& where) {
    std::shared_ptr<const Input> in = open_tiff(file, where);
    const int pages = in->page_count();
    if (pages != in->directories)
        throw InputError(where, "pages",
                         "OpenImageIO reads " + std::to_string(pages) + " of the file's " +
                             std::to_string(in->directories) + " pages");
    const oiio::PageInfo spec0 = in->spec(0);
    check_imagej_stack(spec0, pages, where);
    check_count(std::size_t(pages), where, "pages");
    const Slice first = slice_of(spec0, where, "page 0");
    for (int p = 1; p < pages; ++p) {
        const std::string field = "page " + std::to_string(p);
        const Slice s = slice_of(in->spec(p), where, field);
        if (!(s == first))
            throw InputError(
                where, field,
                describe(s) + ", but page 0 is " + describe(first) + "; every slice must match");
    }
    PlaneStack stack{describe_stack(first, std::uint64_t(pages), where, "pages"), {}, {}};
    stack.size_field = "pages";
    stack.head.spacing = stack_spacing(spec0, stack.head.facts);
    stack.head.files = {file};
    const std::size_t bytes = slice_bytes(stack.head);
    const oiio::Sample sample = sample_of(first.type);
    stack.read = [in, bytes, sample, where](int z0, int z1, std::byte* to) {
        for (int p = z0; p < z1; ++p)
            read_slice(*in, p, to + bytes * std::size_t(p - z0), sample, where);
    };
    return stack;
}

// The folder's slices, each opened and checked before any is read, then each opened again to
// read: a folder may hold more slices than a process may keep open.
PlaneStack read_folder(const fs::path& dir, const std::string& where) {
    std::vector<fs::path> files = slice_files(dir);
    check_count(files.size(), where, "slices");
    Slice first;
    oiio::PageInfo spec0;
    for (const fs::path& f : files) {
        const std::string at = f.string();
        const auto in = open_tiff(f, at);
        if (in->page_count() != 1)
            throw InputError(at, "pages", "a slice of a folder must be a single page");
        const Slice s = slice_of(in->spec(0), at, "slice");
        if (f == files.front()) {
            first = s;
            spec0 = in->spec(0);
        } else if (!(s == first)) {
            throw InputError(at, "size",
                             describe(s) + ", but the first slice (" +
                                 files.front().filename().string() + ") is " + describe(first) +
                                 "; every slice must match");
        }
    }
    PlaneStack stack{describe_stack(first, files.size(), where, "slices"), {}, {}};
    stack.size_field = "slices";
    stack.head.spacing = stack_spacing(spec0, stack.head.facts);
    stack.head.files = files;
    const std::size_t bytes = slice_bytes(stack.head);
    const oiio::Sample sample = sample_of(first.type);
    stack.read = [files, bytes, sample](int z0, int z1, std::byte* to) {
        for (int z = z0; z < z1; ++z) {
            const std::string at = files[std::size_t(z)].string();
            read_slice(*open_tiff(files[std::size_t(z)], at), 0, to + bytes * std::size_t(z - z0),
                       sample, at);
        }
    };
    return stack;
}

}  // namespace

PlaneStack tiff_planes(const fs::path& path) {
    const std::string where = path.string();
    std::error_code ec;
    PlaneStack s = fs::is_directory(path, ec) ? read_folder(path, where) : read_pages(path, where);
    Decoded& d = s.head;
    d.format = "TIFF";
    d.facts.push_back({"slices", std::to_string(d.dims.z) +
                                     (d.files.size() > 1 ? " files" : " pages of one file")});
    return s;
}

Volume read_tiff_stack(const fs::path& path) {
    return read_whole(tiff_planes(path), path.string());
}

}  // namespace isowall::formats
