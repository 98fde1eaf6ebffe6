#include "store/slab_octree.h"

#include <thread>
#include <vector>

namespace isowall::store {
namespace {

template <class T>
class SlabOctreeOf : public SlabOctree {
  public:
    explicit SlabOctreeOf(glm::ivec3 dims)
        : dims_(dims), octree_(MinMaxOctree<T>::start(glm::max(dims - 1, glm::ivec3(0)))) {}

    FiniteRange add_slab(std::span<const std::byte> planes, int z0, int z1, int threads) override {
        VolumeView<T> view;
        view.data = reinterpret_cast<const T*>(planes.data());
        view.dims = dims_;
        constexpr int B = OctreeShape::kLeafCells;
        threads = std::max(1, std::min(threads, (z1 - z0) / B));
        std::vector<FiniteRange> ranges(static_cast<std::size_t>(threads));
        auto cut = [&](int t) { return t == threads ? z1 : z0 + (z1 - z0) * t / threads / B * B; };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads; ++t)
            pool.emplace_back([&, t] {
                ranges[static_cast<std::size_t>(t)] =
                    octree_.leaf_slab(view, cut(t), cut(t + 1), z0);
            });
        ranges[0] = octree_.leaf_slab(view, z0, cut(1), z0);
        for (auto& th : pool) th.join();
        FiniteRange all;
        for (const FiniteRange& r : ranges) all.merge(r);
        return all;
    }

    std::string write(const std::filesystem::path& file, std::uint64_t content_key,
                      const FiniteRange& finite) override {
        octree_.finish(finite);
        const octree_cache::Key key{static_cast<std::uint32_t>(voxel_type_of<T>()), dims_,
                                    content_key};
        std::string why;
        if (!octree_cache::write(file, key, std::as_bytes(octree_.nodes()), octree_.finite_range(),
                                 &why))
            return why.empty() ? "cannot write it" : why;
        return {};
    }

    FiniteRange range() const override { return octree_.finite_range(); }

  private:
    glm::ivec3 dims_;
    MinMaxOctree<T> octree_;
};

}  // namespace

std::unique_ptr<SlabOctree> make_slab_octree(glm::ivec3 dims, VoxelType type) {
    return dispatch_voxel_type(type, [&](auto zero) -> std::unique_ptr<SlabOctree> {
        return std::make_unique<SlabOctreeOf<decltype(zero)>>(dims);
    });
}

}  // namespace isowall::store
