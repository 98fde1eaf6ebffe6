// The tile loop's shows (tile/frame_show.h) with a scripted master on the in-process transport:
// a change that came too soon for its show's interval is shown once the interval has passed even
// while messages keep the tile's inbox full (a flood of an older frame's jobs here), and the last
// picture shown is the tile's final image.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>

#include "comm/inproc_comm.h"
#include "render/renderer.h"
#include "tests/engine_util.h"
#include "tile/tile_loop.h"
#include "volume/phantom.h"
#include "wall_protocol/protocol.h"

namespace isowall {
namespace {

class RecordingShow final : public FrameShow {
  public:
    explicit RecordingShow(double interval_s) : interval_s_(interval_s) {}
    double interval_s() const override { return interval_s_; }
    void show(const Image& tile, std::uint64_t) override {
        const std::lock_guard<std::mutex> hold(lock_);
        last_ = tile;
        ++shows_;
    }
    std::pair<Image, int> seen() {
        const std::lock_guard<std::mutex> hold(lock_);
        return {last_, shows_};
    }

  private:
    double interval_s_;
    std::mutex lock_;
    Image last_;
    int shows_ = 0;
};

// Messages from the tile until one of type T (the others: progress, alive, images).
template <class T>
T await(Comm& comm) {
    for (;;) {
        auto e = comm.receive(1, 30.0);
        if (!e) throw std::runtime_error("the tile sent nothing for 30 s");
        Message m = decode_message(e->tag, e->bytes);
        if (auto* t = std::get_if<T>(&m)) return std::move(*t);
    }
}

TEST(TileLoopShows, TheLastChangeIsShownWhileMessagesKeepTheInboxFull) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    const FrameView fv = test::make_view(p, 80, 60, kPhantomSkinIso);
    constexpr double kInterval = 0.3;
    RecordingShow show(kInterval);
    std::pair<Image, int> after_flood;
    ImageMsg final_image;
    const std::vector<int> codes = run_in_process(2, [&](Comm& comm) {
        if (comm.rank() == 1) {
            auto r = make_renderer("osmesa");
            auto help = make_renderer("osmesa");
            TileSetup setup{*ex, *r, *help, EngineOptions{}, {}, false};
            setup.tile_width = fv.width;
            setup.tile_height = fv.height;
            setup.shows = {&show};
            return run_tile(comm, setup);
        }
        await<TileHelloMsg>(comm);
        send_message(comm, 1, ViewMsg{1, fv});
        send_message(comm, 1,
                     JobMsg{1, 0, 1, 1, Band::fine, fv, PixelRect{0, 0, fv.width, fv.height}});
        await<JobDoneMsg>(comm);
        // The frame is done; its last change may wait for the show's interval. Messages now
        // come faster than the tile takes them, for three intervals: jobs of an older frame,
        // which the tile drops.
        const JobMsg stale{0, 0, 1, 1, Band::fine, fv, PixelRect{0, 0, fv.width, fv.height}};
        const auto t0 = std::chrono::steady_clock::now();
        while (std::chrono::steady_clock::now() - t0 <
               std::chrono::duration<double>(3 * kInterval)) {
            for (int i = 0; i < 100; ++i) send_message(comm, 1, stale);
            while (comm.receive(1, 0)) {
            }
        }
        after_flood = show.seen();
        send_message(comm, 1, QuitMsg{});
        await<TileResultMsg>(comm);  // then the tile image (tile/tile_loop.cpp: quit)
        final_image = await<ImageMsg>(comm);
        send_message(comm, 1, ReleaseMsg{});
        return 0;
    });
    ASSERT_EQ(codes, (std::vector<int>{0, 0}));
    const auto& [shown, shows] = after_flood;
    EXPECT_GE(shows, 1);
    ASSERT_EQ(shown.width, final_image.width);
    ASSERT_EQ(shown.height, final_image.height);
    EXPECT_TRUE(shown.rgba == final_image.rgba) << "the frame's last change was not shown";
}

}  // namespace
}  // namespace isowall
