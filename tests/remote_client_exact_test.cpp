// The client's side of a cells group in two messages (ExactMsg, remote/client_frames.h): the
// stepped group is drawn as it comes, its exact values replace its mesh, and the frame ends on the
// very image the exact groups alone give. An ExactMsg for no awaiting group, a frame that ends
// with a group still stepped, and a stepped group to cache are protocol errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "core/camera.h"
#include "remote/client_frames.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "render/renderer.h"
#include "volume/phantom.h"

namespace isowall::test {
namespace {

using namespace remote;

std::vector<std::byte> as_wire(const std::vector<std::uint8_t>& b) {
    std::vector<std::byte> out(b.size());
    if (!b.empty()) std::memcpy(out.data(), b.data(), b.size());
    return out;
}

// The phantom's skin as a server sends it to a client that takes exact values: each group
// stepped (with its ExactMsg) or, with `exact_only`, exact in one message.
struct SkinMessages {
    RequestMsg request;
    std::vector<GroupMsg> groups;
    std::vector<ExactMsg> exacts;
};

SkinMessages skin_messages(bool exact_only) {
    static const Volume v = make_phantom();
    SkinMessages s;
    const int w = 200, h = 150;
    const Box3 b = v.bounds();
    const Camera cam = fit_depth_range(front_full_view(b, float(w) / h), b);
    s.request.request_id = 4;
    s.request.view = {cam, cam.frustum(float(w) / h), w, h, kPhantomSkinIso, {}};
    for (const Group& g : sample_groups(v, kPhantomSkinIso, 24, 2000)) {
        std::vector<std::uint8_t> exact;
        const auto bytes =
            encode_group(g, GroupEncoding::cells, 0, &v, exact_only ? nullptr : &exact);
        s.groups.push_back({4, g.key(), false, 0, as_wire(bytes)});
        if (!exact.empty()) s.exacts.push_back({4, g.key(), as_wire(exact)});
    }
    return s;
}

EndOfFrameMsg end_of(const SkinMessages& s) {
    EndOfFrameMsg e;
    e.request_id = s.request.request_id;
    return e;
}

Image final_image(const SkinMessages& s, double* c_before_exact, std::uint64_t* exact = nullptr) {
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    frames.begin(s.request, 0);
    double t = 0;
    for (const GroupMsg& g : s.groups) frames.handle(g, 1000, t += 0.01);
    const double before = t;
    for (const ExactMsg& x : s.exacts) frames.handle(x, 100, t += 0.01);
    EXPECT_TRUE(frames.handle(end_of(s), 40, t + 0.01));
    frames.measure();
    for (const ClientSample& sample : frames.result().timeline)
        if (sample.time_s <= before + 1e-9) *c_before_exact = sample.correctness.c;
    if (exact) *exact = frames.result().timeline.back().exact;
    return frames.result().final_image;
}

TEST(ClientExact, TheFrameEndsOnTheImageOfTheExactGroups) {
    const SkinMessages two = skin_messages(false), one = skin_messages(true);
    ASSERT_FALSE(two.exacts.empty()) << "the phantom's gradients go to a step";
    ASSERT_TRUE(one.exacts.empty());
    double c_stepped = 0, c_one = 0;
    std::uint64_t exact_count = 0;
    const Image got = final_image(two, &c_stepped, &exact_count);
    const Image want = final_image(one, &c_one);
    std::printf("%zu groups, %zu stepped; C before the exact values %.5f\n", two.groups.size(),
                two.exacts.size(), c_stepped);
    EXPECT_EQ(got.rgba, want.rgba) << "the final image is the exact groups' to the bit";
    EXPECT_GT(c_stepped, 0.99) << "the stepped groups draw the picture almost right";
    EXPECT_EQ(exact_count, two.exacts.size()) << "the frame counts its exact messages";
    EXPECT_LT(c_stepped, 1.0) << "and not exactly: their normals moved";
}

TEST(ClientExact, AnExactMessageForNoAwaitingGroupIsAProtocolError) {
    const SkinMessages s = skin_messages(false);
    ASSERT_FALSE(s.exacts.empty());
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    frames.begin(s.request, 0);
    EXPECT_THROW(frames.handle(s.exacts[0], 100, 0.1), WireError) << "before its group";
    frames.handle(s.groups[0], 1000, 0.2);
    ExactMsg x = s.exacts[0];
    EXPECT_EQ(x.key, s.groups[0].key);
    frames.handle(x, 100, 0.3);
    EXPECT_THROW(frames.handle(x, 100, 0.4), WireError) << "twice";
    x.request_id = 3;
    EXPECT_NO_THROW(frames.handle(x, 100, 0.5)) << "an older request's is dropped";
}

TEST(ClientExact, AFrameThatEndsWithAGroupStillSteppedIsAProtocolError) {
    const SkinMessages s = skin_messages(false);
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    frames.begin(s.request, 0);
    frames.handle(s.groups[0], 1000, 0.1);
    EXPECT_THROW(frames.handle(end_of(s), 40, 0.2), WireError);
}

TEST(ClientExact, ASteppedGroupToCacheIsAProtocolError) {
    SkinMessages s = skin_messages(false);
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    frames.begin(s.request, 0);
    s.groups[0].cache_gen = 4;
    EXPECT_THROW(frames.handle(s.groups[0], 1000, 0.1), WireError);
}

}  // namespace
}  // namespace isowall::test
