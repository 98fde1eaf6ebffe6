#include "volume/lod_error.h"

#include <chrono>
#include <exception>

namespace isowall {

glm::ivec3 LodErrors::leaf_dims(glm::ivec3 cell_dims) {
    return glm::max((cell_dims + 3) / 4, glm::ivec3(1));
}

glm::ivec3 LodErrors::l1_dims(glm::ivec3 cell_dims) {
    return (leaf_dims(cell_dims) + 1) / 2;
}

std::size_t LodErrors::byte_count(glm::ivec3 cell_dims) {
    const glm::ivec3 l = leaf_dims(cell_dims), n = l1_dims(cell_dims);
    return 2 * static_cast<std::size_t>(l.x) * l.y * l.z +
           static_cast<std::size_t>(n.x) * n.y * n.z;
}

LodErrors::LodErrors(glm::ivec3 cell_dims, std::span<const std::uint8_t> codes)
    : leaf_(leaf_dims(cell_dims)),
      l1_(l1_dims(cell_dims)),
      l1_first_(2 * static_cast<std::size_t>(leaf_.x) * leaf_.y * leaf_.z),
      codes_(codes) {
    for (int c = 0; c < 256; ++c)
        cells_[static_cast<std::size_t>(c)] = lod_code::decode(static_cast<std::uint8_t>(c));
}

namespace {

std::filesystem::path lod_file_for(const OctreeSource& src) {
    std::filesystem::path f = octree_cache::file_for(src.cache_dir, src.volume_path);
    return f.replace_extension(".lod");
}

}  // namespace

LodTable load_or_build_lod(const OctreeSource& src, VoxelType type, glm::ivec3 dims,
                           const std::function<std::vector<std::uint8_t>()>& build) {
    LodTable t;
    const glm::ivec3 cells = glm::max(dims - 1, glm::ivec3(0));
    const std::size_t bytes = LodErrors::byte_count(cells);
    std::optional<octree_cache::Key> key;
    std::filesystem::path file;
    const std::vector<std::filesystem::path> sources = src.key_files();
    if (!src.volume_path.empty() && !src.cache_dir.empty() && !sources.empty() &&
        (key = octree_cache::key_for(sources, type, dims))) {
        file = lod_file_for(src);
        std::error_code ec;
        if (std::filesystem::exists(file, ec)) {
            try {
                auto mapped = std::make_shared<MappedFile>(file, true);
                if (auto hit = octree_cache::match(*mapped, *key, bytes, &t.cache_note)) {
                    t.errors = LodErrors(
                        cells, {reinterpret_cast<const std::uint8_t*>(hit->nodes.data()), bytes});
                    t.mapped = std::move(mapped);
                    t.from_cache = true;
                    return t;
                }
            } catch (const std::exception& e) {
                t.cache_note = e.what();
            }
        }
    }
    const auto t0 = std::chrono::steady_clock::now();
    t.owned = build();
    t.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.errors = LodErrors(cells, t.owned);
    std::string note;
    if (key &&
        !octree_cache::write(file, *key, std::as_bytes(std::span(t.owned)), FiniteRange{}, &note))
        t.cache_note += (t.cache_note.empty() ? "" : "; ") + note;
    return t;
}

}  // namespace isowall
