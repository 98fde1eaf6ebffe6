// DICOM through GDCM: its Scanner reads the few header fields of every file in the folder, its
// ImageReader decodes each slice's pixels in whatever transfer syntax GDCM supports (raw, RLE,
// deflate, JPEG lossless, JPEG-LS through CharLS, JPEG 2000 through OpenJPEG). What we do: choose
// the series, order the slices (dicom_slices.h), check each slice's pixels, and scale.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include <gdcmDirectory.h>
#include <gdcmImageHelper.h>
#include <gdcmImageReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>
#include <gdcmUIDs.h>

#include "core/error.h"
#include "readers/dicom_lengths.h"
#include "readers/dicom_slices.h"
#include "readers/plane_stack.h"
#include "readers/readers.h"
#include "readers/voxel_ops.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

const gdcm::Tag kSeriesUid(0x0020, 0x000e), kPosition(0x0020, 0x0032), kOrientation(0x0020, 0x0037),
    kRows(0x0028, 0x0010), kColumns(0x0028, 0x0011), kPixelSpacing(0x0028, 0x0030),
    kModality(0x0008, 0x0060), kDescription(0x0008, 0x103e), kSeriesNumber(0x0020, 0x0011),
    kPixelData(0x7fe0, 0x0010), kBitsAllocated(0x0028, 0x0100), kFrames(0x0028, 0x0008),
    kRescaleIntercept(0x0028, 0x1052), kRescaleSlope(0x0028, 0x1053);

std::string trimmed(const char* v) {
    std::string s = v ? v : "";
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    return s;
}

// The numbers of a backslash-separated decimal string ("0.41\0.41").
std::vector<double> numbers(const std::string& text) {
    std::vector<double> out;
    std::stringstream in(text);
    std::string piece;
    while (std::getline(in, piece, '\\')) {
        char* end = nullptr;
        const double v = std::strtod(piece.c_str(), &end);
        if (end == piece.c_str() || !std::isfinite(v)) return {};
        out.push_back(v);
    }
    return out;
}

struct Series {
    std::vector<std::string> files;
    std::string description, number, modality;
};

// The DICOM Part 10 files among `files`, each checked (dicom_lengths.h) before GDCM reads it;
// other files (notes, a DICOMDIR is Part 10 too and has no series) are passed over after their
// first 132 bytes, so a large file beside the series costs nothing. A FIFO or device in the folder
// is named: opening one could block, and a series with one in it is not what it seems.
gdcm::Directory::FilenamesType part10_files(const gdcm::Directory::FilenamesType& files) {
    constexpr std::size_t kMagicEnd = 132;  // a 128-byte preamble, then "DICM"
    gdcm::Directory::FilenamesType out;
    for (const std::string& f : files) {
        check_regular_file(f, f, "DICOM");
        std::ifstream in(f, std::ios::binary);
        std::vector<char> text(kMagicEnd);
        in.read(text.data(), std::streamsize(text.size()));
        text.resize(std::size_t(in.gcount()));
        if (!has_part10_magic(std::as_bytes(std::span(text)))) continue;
        text.insert(text.end(), std::istreambuf_iterator<char>(in),
                    std::istreambuf_iterator<char>());
        const auto bytes = std::as_bytes(std::span(text));
        if (std::string problem = dicom_length_problem(bytes); !problem.empty())
            throw InputError(f, "DICOM", problem + " (a damaged file)");
        out.push_back(f);
    }
    return out;
}

// The folder's DICOM files by series (files that are not DICOM, or have no series, are passed
// over: a scanner's folder may hold a DICOMDIR or notes).
std::map<std::string, Series> scan_series(const fs::path& dir, gdcm::Scanner& scanner) {
    // GDCM passes over what is not a regular file; a FIFO or device where a slice may belong is
    // named instead (the series would read as missing a slice, and opening one could block).
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec))
        if (!e.is_directory(ec) && !e.is_regular_file(ec))
            check_regular_file(e.path(), e.path().string(), "DICOM");
    gdcm::Directory d;
    d.Load(dir.string(), false);
    for (const gdcm::Tag& t : {kSeriesUid, kPosition, kOrientation, kRows, kColumns, kPixelSpacing,
                               kModality, kDescription, kSeriesNumber, kBitsAllocated, kFrames})
        scanner.AddTag(t);
    gdcm::Directory::FilenamesType files = part10_files(d.GetFilenames());
    std::sort(files.begin(), files.end());
    scanner.Scan(files);
    std::map<std::string, Series> out;
    for (const std::string& f : files) {
        const std::string uid = trimmed(scanner.GetValue(f.c_str(), kSeriesUid));
        if (uid.empty()) continue;
        Series& s = out[uid];
        s.files.push_back(f);
        s.description = trimmed(scanner.GetValue(f.c_str(), kDescription));
        s.number = trimmed(scanner.GetValue(f.c_str(), kSeriesNumber));
        s.modality = trimmed(scanner.GetValue(f.c_str(), kModality));
    }
    return out;
}

std::string series_label(const std::string& uid, const Series& s) {
    std::string label = "series " + (s.number.empty() ? uid : s.number);
    if (!s.description.empty()) label += " \"" + s.description + "\"";
    return label + " (" + std::to_string(s.files.size()) + " files)";
}

// The series to read: the one of `file` when a file was named, the folder's only one otherwise.
const std::pair<const std::string, Series>& choose_series(const std::map<std::string, Series>& all,
                                                          const fs::path& path,
                                                          const std::string& file,
                                                          const gdcm::Scanner& scanner) {
    if (all.empty())
        throw InputError(path.string(), "SeriesInstanceUID",
                         "no DICOM image series here (no file GDCM reads with a series UID)");
    if (!file.empty()) {
        const std::string uid = trimmed(scanner.GetValue(file.c_str(), kSeriesUid));
        const auto it = all.find(uid);
        if (it == all.end())
            throw InputError(file, "SeriesInstanceUID", "not a DICOM image of a series");
        return *it;
    }
    if (all.size() > 1) {
        std::string list;
        for (const auto& [uid, s] : all) list += (list.empty() ? "" : "; ") + series_label(uid, s);
        throw InputError(path.string(), "SeriesInstanceUID",
                         std::to_string(all.size()) + " series in one folder (" + list +
                             "): give --volume one file of the series to read");
    }
    return *all.begin();
}

std::optional<VoxelType> voxel_type_of_pixels(const gdcm::PixelFormat& p) {
    switch (p.GetScalarType()) {
        case gdcm::PixelFormat::UINT8:
            return VoxelType::u8;
        case gdcm::PixelFormat::INT8:
            return VoxelType::i8;
        case gdcm::PixelFormat::UINT12:
        case gdcm::PixelFormat::UINT16:
            return VoxelType::u16;
        case gdcm::PixelFormat::INT12:
        case gdcm::PixelFormat::INT16:
            return VoxelType::i16;
        case gdcm::PixelFormat::UINT32:
            return VoxelType::u32;
        case gdcm::PixelFormat::INT32:
            return VoxelType::i32;
        case gdcm::PixelFormat::FLOAT32:
            return VoxelType::f32;
        case gdcm::PixelFormat::FLOAT64:
            return VoxelType::f64;
        default:
            return std::nullopt;
    }
}

SliceHeader slice_header(const std::string& f, const gdcm::Scanner& scanner) {
    SliceHeader h;
    h.file = f;
    const std::vector<double> pos = numbers(trimmed(scanner.GetValue(f.c_str(), kPosition)));
    if (pos.size() != 3)
        throw InputError(f, "ImagePositionPatient", "missing or not three numbers");
    const std::vector<double> dir = numbers(trimmed(scanner.GetValue(f.c_str(), kOrientation)));
    if (dir.size() != 6)
        throw InputError(f, "ImageOrientationPatient", "missing or not six numbers");
    h.position = {pos[0], pos[1], pos[2]};
    h.row = {dir[0], dir[1], dir[2]};
    h.column = {dir[3], dir[4], dir[5]};
    h.rows = std::atoi(trimmed(scanner.GetValue(f.c_str(), kRows)).c_str());
    h.columns = std::atoi(trimmed(scanner.GetValue(f.c_str(), kColumns)).c_str());
    const int bits = std::atoi(trimmed(scanner.GetValue(f.c_str(), kBitsAllocated)).c_str());
    if (std::uint64_t(std::max(h.rows, 0)) * std::uint64_t(std::max(h.columns, 0)) *
            std::uint64_t(std::max(bits, 8) / 8) >
        kMaxSliceBytes)
        throw InputError(f, "Rows/Columns",
                         std::to_string(h.columns) + "x" + std::to_string(h.rows) + " at " +
                             std::to_string(bits) + " bits is more than " +
                             std::to_string(kMaxSliceBytes >> 20) + " MiB a slice");
    if (std::atoi(trimmed(scanner.GetValue(f.c_str(), kFrames)).c_str()) > 1)
        throw InputError(f, "NumberOfFrames",
                         "a multi-frame file (" + trimmed(scanner.GetValue(f.c_str(), kFrames)) +
                             " frames); isowall reads series of single-frame files");
    return h;
}

// "JPEG-LS Lossless Image Compression (1.2.840.10008.1.2.4.80)".
std::string transfer_syntax_text(const gdcm::TransferSyntax& ts) {
    const char* uid = gdcm::TransferSyntax::GetTSString(ts);
    gdcm::UIDs names;
    if (!uid || !names.SetFromUID(uid)) return uid ? uid : "unknown";
    return std::string(names.GetName()) + " (" + uid + ")";
}

struct SlicePixels {
    VoxelType type;
    Scaling scaling;
    std::string transfer_syntax;
    std::vector<std::byte> bytes;
    std::pair<double, double> stored_range;  // what BitsStored and PixelRepresentation allow
};

// One slice's pixels, decoded, of the type of the series' first slice when `expected` is set.
SlicePixels read_slice(const SliceHeader& h, const std::optional<VoxelType>& expected) {
    const std::string& f = h.file;
    gdcm::ImageReader reader;
    reader.SetFileName(f.c_str());
    if (!reader.Read())
        throw InputError(f, "PixelData",
                         "no image GDCM decodes (no pixel data, or a transfer syntax it lacks)");
    const gdcm::Image& img = reader.GetImage();
    const gdcm::PixelFormat& pf = img.GetPixelFormat();
    if (pf.GetSamplesPerPixel() != 1)
        throw InputError(
            f, "SamplesPerPixel",
            std::to_string(pf.GetSamplesPerPixel()) + " (colour); a volume is one value per voxel");
    const auto type = voxel_type_of_pixels(pf);
    if (!type)
        throw InputError(
            f, "BitsAllocated",
            std::string(pf.GetScalarTypeAsString()) + " pixels are not a type isowall reads");
    if (expected && *type != *expected)
        throw InputError(f, "PixelRepresentation",
                         std::string(type_name(*type)) +
                             " pixels where the series' first slice has " +
                             std::string(type_name(*expected)));
    const std::size_t need = std::size_t(h.rows) * std::size_t(h.columns) * voxel_size(*type);
    const auto wrong_size = [&](std::uint64_t have) {
        return InputError(f, "PixelData",
                          std::to_string(have) + " bytes of pixels where " +
                              std::to_string(h.columns) + "x" + std::to_string(h.rows) + " " +
                              std::string(type_name(*type)) + " needs " + std::to_string(need));
    };
    // Uncompressed pixels must all be there before a buffer of the header's size is made.
    const gdcm::DataElement& pd = reader.GetFile().GetDataSet().GetDataElement(kPixelData);
    if (const gdcm::ByteValue* bv = pd.GetByteValue(); bv && bv->GetLength() < need)
        throw wrong_size(bv->GetLength());
    if (img.GetDimension(0) != unsigned(h.columns) || img.GetDimension(1) != unsigned(h.rows) ||
        img.GetBufferLength() != need)
        throw wrong_size(img.GetBufferLength());
    const int bits = std::clamp(int(pf.GetBitsStored()), 1, int(voxel_size(*type) * 8));
    const bool is_signed = pf.GetPixelRepresentation() == 1;
    const double span = std::ldexp(1.0, bits);
    SlicePixels out{*type,
                    {img.GetSlope(), img.GetIntercept()},
                    transfer_syntax_text(img.GetTransferSyntax()),
                    std::vector<std::byte>(need),
                    is_signed ? std::pair{-span / 2, span / 2 - 1} : std::pair{0.0, span - 1}};
    if (!img.GetBuffer(reinterpret_cast<char*>(out.bytes.data())))
        throw InputError(f, "PixelData", "GDCM could not decode the pixels");
    return out;
}

// A slice's scaling as GDCM's image reader will apply it (its rules for which modalities a
// Rescale applies to), from the header alone.
Scaling gdcm_scaling(const std::string& f) {
    gdcm::Reader reader;
    reader.SetFileName(f.c_str());
    if (!reader.ReadUpToTag(kPixelData))
        throw InputError(f, "DICOM", "GDCM cannot read its header (a damaged file)");
    // GDCM reads an unparsable or non-finite RescaleSlope as some number and a slope of 0 as 1:
    // the header's own text is checked first, so a damaged one is named, not guessed.
    const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
    for (const auto& [tag, field] : {std::pair{kRescaleSlope, "RescaleSlope"},
                                     std::pair{kRescaleIntercept, "RescaleIntercept"}}) {
        if (!ds.FindDataElement(tag)) continue;
        const gdcm::ByteValue* v = ds.GetDataElement(tag).GetByteValue();
        if (!v) continue;
        const std::string text = trimmed(std::string(v->GetPointer(), v->GetLength()).c_str());
        if (text.empty()) continue;
        const std::vector<double> n = numbers(text);
        if (n.size() != 1)
            throw InputError(f, field,
                             "expected one finite decimal number, got " + quote_bounded(text));
        if (tag == kRescaleSlope && n[0] == 0)
            throw InputError(f, field, "a slope of 0 makes every voxel the same value");
    }
    const std::vector<double> is =
        gdcm::ImageHelper::GetRescaleInterceptSlopeValue(reader.GetFile());
    return is.size() == 2 ? Scaling{is[1], is[0]} : Scaling{};
}

// What the stack's reads share: the slices in order, and the first one's pixels, decoded to learn
// the series' type (kept for the first read).
struct SeriesSlices {
    std::vector<SliceHeader> headers;  // in slice order
    std::vector<Scaling> scalings;     // each slice's, from its header
    bool per_slice = false;            // slices scaled each its own way: float32 values
    std::optional<SlicePixels> first;
};

// The slices in order, each one's scaling from its header, and the first one's pixels.
std::shared_ptr<SeriesSlices> series_slices(const std::vector<SliceHeader>& headers,
                                            const SliceOrder& order) {
    auto slices = std::make_shared<SeriesSlices>();
    for (const std::size_t k : order.order) {
        slices->headers.push_back(headers[k]);
        slices->scalings.push_back(gdcm_scaling(headers[k].file));
    }
    slices->first = read_slice(slices->headers.front(), std::nullopt);
    const std::vector<Scaling>& sc = slices->scalings;
    slices->per_slice = !std::all_of(sc.begin(), sc.end(), [&](const Scaling& s) {
        return s.slope == sc[0].slope && s.intercept == sc[0].intercept;
    });
    return slices;
}

// A series scaled slice by slice lands in float32: each slice's scaling, against the stored
// values its header allows, must keep every value finite there.
void check_slice_scalings(const SeriesSlices& slices) {
    const auto [lo, hi] = slices.first->stored_range;
    for (std::size_t k = 0; k < slices.scalings.size(); ++k)
        if (std::string p = scaling_problem(slices.scalings[k], lo, hi, VoxelType::f32); !p.empty())
            throw InputError(slices.headers[k].file, "RescaleSlope", p);
}

}  // namespace

// The series' name in errors: the folder, or the folder of the file named.
std::string series_where(const fs::path& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return path.string();
    return path.parent_path().empty() ? std::string(".") : path.parent_path().string();
}

PlaneStack dicom_planes(const fs::path& path) {
    gdcm::Trace::SetWarning(false);  // its warnings go to stderr; ours is the one line
    gdcm::Trace::SetError(false);
    std::error_code ec;
    const bool folder = fs::is_directory(path, ec);
    const fs::path dir = folder ? path : path.parent_path().empty() ? "." : path.parent_path();
    gdcm::Scanner scanner;
    const std::map<std::string, Series> all = scan_series(dir, scanner);
    const auto& [uid, series] = choose_series(all, path, folder ? "" : path.string(), scanner);
    const std::string where = series_where(path);
    std::vector<SliceHeader> headers;
    for (const std::string& f : series.files) headers.push_back(slice_header(f, scanner));
    const SliceOrder order = order_slices(headers, where);
    const std::vector<double> ps =
        numbers(trimmed(scanner.GetValue(series.files.front().c_str(), kPixelSpacing)));
    if (ps.size() != 2)
        throw InputError(series.files.front(), "PixelSpacing", "missing or not two numbers");
    const std::shared_ptr<SeriesSlices> slices = series_slices(headers, order);
    const SliceHeader& first = slices->headers.front();

    PlaneStack stack;
    Decoded& d = stack.head;
    d.spacing = {float(ps[1]), float(ps[0]), float(order.spacing)};  // PixelSpacing: row, column
    d.type = slices->per_slice ? VoxelType::f32 : slices->first->type;
    d.dims = checked_dims(
        where, "Rows/Columns",
        std::vector<std::uint64_t>{std::uint64_t(first.columns), std::uint64_t(first.rows),
                                   std::uint64_t(headers.size())},
        d.type);
    if (slices->per_slice) {
        d.facts.push_back({"scaling", "RescaleSlope/Intercept per slice (applied: float32)"});
        check_slice_scalings(*slices);
    } else {
        d.scaling = slices->first->scaling;
    }
    stack.declared_range = slices->first->stored_range;
    d.orientation.axes =
        glm::mat3(glm::vec3(first.row), glm::vec3(first.column), glm::vec3(order.normal));
    d.orientation.origin = glm::vec3(first.position);
    d.orientation.known = true;
    d.format = "DICOM";
    d.files.assign(series.files.begin(), series.files.end());
    if (!series.modality.empty()) d.facts.push_back({"modality", series.modality});
    d.facts.push_back({"series", series_label(uid, series)});
    d.facts.push_back({"slices", std::to_string(headers.size()) + ", " +
                                     std::to_string(order.spacing) + " mm apart"});
    d.facts.push_back({"transfer syntax", slices->first->transfer_syntax});
    stack.size_field = "Rows/Columns";
    stack.scaling_field = "RescaleSlope";
    const VoxelType stored = slices->first->type;
    const Scaling one = d.scaling;
    stack.read = [slices, stored, one](int z0, int z1, std::byte* to) {
        for (int z = z0; z < z1; ++z) {
            const SliceHeader& h = slices->headers[std::size_t(z)];
            SlicePixels p = z == 0 && slices->first ? std::move(*slices->first)
                                                    : read_slice(h, std::optional(stored));
            if (z == 0) slices->first.reset();
            const std::size_t n = p.bytes.size() / voxel_size(stored);
            if (slices->per_slice) {
                const std::vector<std::byte> v = to_float32(p.bytes, stored, p.scaling);
                std::memcpy(to + std::size_t(z - z0) * n * 4, v.data(), v.size());
                continue;
            }
            // The series' one scaling was read from the headers; the pixels' must agree.
            if (p.scaling.slope != one.slope || p.scaling.intercept != one.intercept)
                throw InputError(h.file, "RescaleSlope",
                                 "differs between the slice's header and its image");
            std::memcpy(to + std::size_t(z - z0) * p.bytes.size(), p.bytes.data(), p.bytes.size());
        }
    };
    return stack;
}

Volume read_dicom(const fs::path& path) {
    return read_whole(dicom_planes(path), series_where(path));
}

}  // namespace isowall::formats
