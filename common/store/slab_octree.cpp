#include "common/store/slab_octree.h"

#include <thread>
#include <vector>

namespace isowall::store {
namespace {

template <class T>
class SlabOctreeOf : public SlabOctree {
  public:
    explicit SlabOctreeOf(const Volume& v)
        : view_(v.view<T>()), octree_(MinMaxOctree<T>::start(view_.cell_dims())) {}

    FiniteRange add_slab(int z0, int z1, int threads) override {
        constexpr int B = OctreeShape::kLeafCells;
        threads = std::max(1, std::min(threads, (z1 - z0) / B));
        std::vector<FiniteRange> ranges(static_cast<std::size_t>(threads));
        auto cut = [&](int t) { return t == threads ? z1 : z0 + (z1 - z0) * t / threads / B * B; };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads; ++t)
            pool.emplace_back([&, t] {
                ranges[static_cast<std::size_t>(t)] = octree_.leaf_slab(view_, cut(t), cut(t + 1));
            });
        ranges[0] = octree_.leaf_slab(view_, z0, cut(1));
        for (auto& th : pool) th.join();
        FiniteRange all;
        for (const FiniteRange& r : ranges) all.merge(r);
        return all;
    }

    std::string write(const std::filesystem::path& file, std::uint64_t content_key,
                      const FiniteRange& finite) override {
        octree_.finish(finite);
        const octree_cache::Key key{static_cast<std::uint32_t>(voxel_type_of<T>()), view_.dims,
                                    content_key};
        std::string why;
        if (!octree_cache::write(file, key, std::as_bytes(octree_.nodes()), octree_.finite_range(),
                                 &why))
            return why.empty() ? "cannot write it" : why;
        return {};
    }

    FiniteRange range() const override { return octree_.finite_range(); }

  private:
    VolumeView<T> view_;
    MinMaxOctree<T> octree_;
};

}  // namespace

std::unique_ptr<SlabOctree> make_slab_octree(const Volume& volume) {
    return dispatch_voxel_type(volume.type(), [&](auto zero) -> std::unique_ptr<SlabOctree> {
        return std::make_unique<SlabOctreeOf<decltype(zero)>>(volume);
    });
}

}  // namespace isowall::store
