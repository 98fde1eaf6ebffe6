#pragma once
// Shared by the remote-viewing tests: a server on a loopback port of its own, serving the
// phantom from a thread, and the local image a client's frame must equal.
#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "app/whole_frame.h"
#include "core/camera.h"
#include "engine/progressive_engine.h"
#include "remote/view_server.h"
#include "render/renderer.h"
#include "tests/image_compare.h"
#include "volume/phantom.h"

namespace isowall::test {

// A hello for the phantom, in `encoding` (3: compact and zstd, what `view` asks by default).
inline remote::HelloMsg phantom_hello(std::uint8_t encoding = 3) {
    remote::HelloMsg h;
    h.dataset = "phantom";
    h.encoding = encoding;
    return h;
}

inline remote::Dataset phantom_dataset() {
    remote::Dataset d;
    d.name = "phantom";
    d.volume = std::make_unique<Volume>(make_phantom());
    d.extractor = make_surface_extractor(*d.volume);
    return d;
}

// A ViewServer on 127.0.0.1:<any free port>, serving until destroyed.
class TestServer {
  public:
    explicit TestServer(remote::ServerOptions o = {}) {
        o.address = "127.0.0.1";
        o.port = 0;
        o.verbose = false;
        o.hello_timeout_s = 5;
        std::vector<remote::Dataset> ds;
        ds.push_back(phantom_dataset());
        server_ = std::make_unique<remote::ViewServer>(std::move(ds), o);
        thread_ = std::thread([this] { server_->serve(stop_); });
    }
    ~TestServer() {
        stop_ = true;
        thread_.join();
        server_.reset();
    }
    int port() const { return server_->port(); }
    remote::ViewServer& server() { return *server_; }

  private:
    std::unique_ptr<remote::ViewServer> server_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

// The front view of a volume of `bounds` at `w` x `h`, turned by yaw degrees, at `iso`.
inline FrameView front_view(const Box3& bounds, int w, int h, double yaw, double iso) {
    Camera c = front_full_view(bounds, float(w) / float(h));
    c = fit_depth_range(orbit(c, yaw, 0), bounds);
    return {c, c.frustum(float(w) / float(h)), w, h, iso, {}};
}

// The front view of the phantom at `w` x `h`, turned by yaw degrees, at `iso`. The phantom is
// built once for its bounds: building it for each view took a client under the sanitizers
// longer than a server's idle limit (RemoteIdle).
inline FrameView phantom_view(int w, int h, double yaw, double iso = kPhantomSkinIso) {
    static const Box3 bounds = make_phantom().bounds();
    return front_view(bounds, w, h, yaw, iso);
}

// What `isowall render` shows of `view` (the progressive engine's final image).
inline Image local_image(const FrameView& view) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v);
    auto r = make_renderer("osmesa");
    ProgressiveEngine engine(*ex);
    return draw_frame(engine, view, *r).final_image;
}

// The thresholds every final-image test of the engine uses.
inline void expect_same_image(const Image& got, const Image& want, const std::string& what) {
    const ImageComparison c = compare_images(got, want);
    EXPECT_GE(c.mask_iou, 0.999) << what << ": " << c;
    EXPECT_GE(c.equal_share, 0.999) << what << ": " << c;
}

}  // namespace isowall::test
