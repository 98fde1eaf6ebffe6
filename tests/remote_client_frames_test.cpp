// The client's frame without a server: groups of a coarse level and then the full-resolution
// level, as progressive LOD sends them, and the correctness the client measures along the way.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <utility>

#include "core/camera.h"
#include "remote/client_frames.h"
#include "remote/group_codec.h"
#include "render/renderer.h"

namespace isowall::test {
namespace {

using namespace remote;

// An axis-aligned box's six faces, counter-clockwise seen from outside.
Mesh box_mesh(glm::vec3 lo, glm::vec3 hi) {
    Mesh m;
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            glm::vec3 n(0);
            n[axis] = side ? 1.0f : -1.0f;
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const auto base = static_cast<std::uint32_t>(m.positions.size());
            for (int corner = 0; corner < 4; ++corner) {
                glm::vec3 p;
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = (corner == 1 || corner == 2) ? hi[u] : lo[u];
                p[v] = (corner >= 2) ? hi[v] : lo[v];
                m.positions.push_back(p);
                m.normals.push_back(n);
            }
            for (std::uint32_t t : {1u, 2u}) {  // triangles (0,1,2) and (0,2,3) of the quad
                std::uint32_t a = base, b = base + t, c = base + t + 1;
                const glm::vec3 face =
                    glm::cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
                if (glm::dot(face, n) < 0) std::swap(b, c);
                m.indices.insert(m.indices.end(), {a, b, c});
            }
        }
    }
    return m;
}

GroupMsg group_msg(std::uint64_t request, const Mesh& mesh, int level, int seed_x, double iso) {
    Group g;
    g.seed = {seed_x, 0, 0};
    g.level = level;
    g.iso = iso;
    g.mesh = mesh;
    GroupMsg m;
    m.request_id = request;
    m.key = g.key();
    const std::vector<std::uint8_t> bytes = encode_group(g, GroupEncoding::indexed);
    m.encoded.resize(bytes.size());
    std::memcpy(m.encoded.data(), bytes.data(), bytes.size());
    return m;
}

TEST(ClientFrames, CoarsePixelsStayDrawnAfterTheDepthClearOfAFinerLevel) {
    const Box3 bounds{glm::vec3(-1), glm::vec3(1)};
    const int w = 160, h = 120;
    Camera cam = fit_depth_range(front_full_view(bounds, float(w) / h), bounds);
    RequestMsg req;
    req.request_id = 1;
    req.view = {cam, cam.frustum(float(w) / h), w, h, 7.0, {}};
    req.lod = LodSchedule::on;

    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    frames.begin(req, 0.0);
    // Level 2: one box around both halves of the final surface. Then level 0: the left half,
    // then the right half. The depth clear before the left half must not make the coarse
    // colour on the right half count as "not drawn".
    const Mesh coarse = box_mesh(glm::vec3(-0.8f), glm::vec3(0.8f));
    const Mesh left = box_mesh(glm::vec3(-0.7f), glm::vec3(-0.02f, 0.7f, 0.7f));
    const Mesh right = box_mesh(glm::vec3(0.02f, -0.7f, -0.7f), glm::vec3(0.7f));
    double t = 0;
    for (const auto& [mesh, level] : {std::pair{coarse, 2}, {left, 0}, {right, 0}}) {
        t += 1.0;  // past the sampling interval: one sample per group
        EXPECT_FALSE(frames.handle(group_msg(1, mesh, level, int(t), 7.0), 1000, t));
    }
    EndOfFrameMsg end;
    end.request_id = 1;
    ASSERT_TRUE(frames.handle(end, 40, t + 1));
    frames.measure();
    const auto& line = frames.result().timeline;
    ASSERT_GE(line.size(), 5u);  // begin, three groups, end
    const double after_coarse = line[1].correctness.c;
    const double after_left = line[2].correctness.c;
    EXPECT_GT(after_coarse, 0.5) << "the coarse box covers every final pixel";
    EXPECT_GE(after_left, after_coarse)
        << "the left half is exact now and the right half still shows the coarse colour";
    EXPECT_DOUBLE_EQ(line.back().correctness.c, 1.0);
}

// The cache follows the server's generations: a group of another generation drops the cache,
// a named slot is an index into it, and named groups are drawn coarse levels first.
TEST(ClientFrames, TheCacheFollowsTheServersGenerationsAndDrawsNamedSlotsCoarseFirst) {
    const Box3 bounds{glm::vec3(-1), glm::vec3(1)};
    const int w = 64, h = 48;
    Camera cam = fit_depth_range(front_full_view(bounds, float(w) / h), bounds);
    RequestMsg req;
    req.view = {cam, cam.frustum(float(w) / h), w, h, 7.0, {}};
    req.lod = LodSchedule::on;
    req.cached_groups = true;
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    const Mesh fine = box_mesh(glm::vec3(-0.5f), glm::vec3(0.5f));
    const Mesh coarse = box_mesh(glm::vec3(-0.8f), glm::vec3(0.8f));
    const auto cached = [&](std::uint64_t request, const Mesh& mesh, int level, int seed_x,
                            std::uint64_t gen) {
        GroupMsg m = group_msg(request, mesh, level, seed_x, 7.0);
        m.cache_gen = gen;
        return m;
    };
    req.request_id = 1;
    frames.begin(req, 0);
    frames.handle(cached(1, fine, 0, 0, 1), 100, 0);    // generation 1, slot 0
    frames.handle(cached(1, coarse, 2, 1, 1), 100, 0);  // slot 1
    req.request_id = 2;
    frames.begin(req, 1);
    // Slot 0 is finer than slot 1: in slot order the coarse one would be skipped.
    frames.handle(VisibleMsg{2, {0, 1}}, 20, 1);
    EndOfFrameMsg end;
    end.request_id = 2;
    ASSERT_TRUE(frames.handle(end, 40, 1));
    EXPECT_EQ(frames.result().timeline.back().named, 2u);
    EXPECT_EQ(frames.result().timeline.back().triangles, 24u) << "both named groups drawn";
    // A late group of an older request in another generation: the cache holds it alone.
    req.request_id = 3;
    frames.begin(req, 2);
    frames.handle(cached(2, fine, 0, 2, 2), 100, 2);
    EXPECT_NO_THROW(frames.handle(VisibleMsg{3, {0}}, 20, 2));
    try {
        frames.handle(VisibleMsg{3, {0, 1}}, 20, 2);
        ADD_FAILURE() << "slot 1 of generation 2 does not exist";
    } catch (const WireError& e) {
        EXPECT_NE(std::string(e.what()).find("visible message: slots: the server named a group "
                                             "the client does not hold (slot 1 of 1)"),
                  std::string::npos)
            << e.what();
    }
}

// What an adaptive client tells the server (DecodeRateMsg): the triangles it decoded per
// encoding since its last report, at most every kReportEveryS, and nothing when it decoded none.
TEST(ClientFrames, DecodeReportsCountTheTrianglesOfEachEncoding) {
    const Box3 bounds{glm::vec3(-1), glm::vec3(1)};
    Camera cam = fit_depth_range(front_full_view(bounds, 4.0f / 3), bounds);
    RequestMsg req;
    req.request_id = 1;
    req.view = {cam, cam.frustum(4.0f / 3), 32, 24, 7.0, {}};
    auto renderer = make_renderer("osmesa");
    ClientFrames frames(*renderer);
    EXPECT_FALSE(frames.decode_report(1.0)) << "nothing decoded yet";
    frames.begin(req, 1.0);
    const Mesh box = box_mesh(glm::vec3(-0.5f), glm::vec3(0.5f));
    frames.handle(group_msg(1, box, 0, 0, 7.0), 100, 1.0);
    frames.handle(group_msg(1, box, 0, 1, 7.0), 100, 1.0);
    const auto report = frames.decode_report(1.0);
    ASSERT_TRUE(report);
    ASSERT_EQ(report->entries.size(), 1u);
    EXPECT_EQ(report->entries[0].encoding, static_cast<std::uint8_t>(GroupEncoding::indexed));
    EXPECT_EQ(report->entries[0].triangles, 24u);
    EXPECT_GE(report->entries[0].seconds, 0.0);
    frames.handle(group_msg(1, box, 0, 2, 7.0), 100, 1.01);
    EXPECT_FALSE(frames.decode_report(1.01)) << "too soon after the last";
    const auto next = frames.decode_report(1.0 + ClientFrames::kReportEveryS);
    ASSERT_TRUE(next);
    EXPECT_EQ(next->entries[0].triangles, 12u) << "counted since the last report";
}

}  // namespace
}  // namespace isowall::test
