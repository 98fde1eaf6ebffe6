// Shared by the remote-viewing protocol tests (remote_protocol_test.cpp,
// remote_protocol_malformed_test.cpp): equality for the messages, a sample of each with every
// field set to something other than its default, and expect_view_wire_error.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "remote/view_framing.h"
#include "tests/protocol_test_util.h"  // equality of FrameView and its parts

namespace isowall::remote {

inline bool operator==(const HelloMsg& a, const HelloMsg& b) {
    return a.protocol_version == b.protocol_version && a.dataset == b.dataset &&
           a.token == b.token && a.encoding == b.encoding && a.role == b.role &&
           a.session == b.session && a.takes_exact == b.takes_exact;
}
inline bool operator==(const ExactMsg& a, const ExactMsg& b) {
    return a.request_id == b.request_id && a.key == b.key && a.bits == b.bits;
}
inline bool operator==(const SessionMsg& a, const SessionMsg& b) {
    return a.session == b.session && a.presenter == b.presenter && a.members == b.members;
}
inline bool operator==(const ReadyMsg& a, const ReadyMsg& b) {
    return a.bounds.min == b.bounds.min && a.bounds.max == b.bounds.max &&
           a.value_min == b.value_min && a.value_max == b.value_max && a.dims == b.dims &&
           a.spacing == b.spacing && a.axes == b.axes;
}
inline bool operator==(const RequestMsg& a, const RequestMsg& b) {
    return a.request_id == b.request_id && a.view == b.view && a.lod == b.lod &&
           a.cached_groups == b.cached_groups;
}
inline bool operator==(const GroupMsg& a, const GroupMsg& b) {
    return a.request_id == b.request_id && a.key == b.key &&
           a.draw_from_next_frame == b.draw_from_next_frame && a.cache_gen == b.cache_gen &&
           a.encoded == b.encoded;
}
inline bool operator==(const VisibleMsg& a, const VisibleMsg& b) {
    return a.request_id == b.request_id && a.slots == b.slots;
}
inline bool operator==(const EndOfFrameMsg& a, const EndOfFrameMsg& b) {
    return a.request_id == b.request_id && a.rays == b.rays && a.groups == b.groups &&
           a.triangles == b.triangles && a.bytes == b.bytes;
}
inline bool operator==(const ErrorMsg& a, const ErrorMsg& b) {
    return a.code == b.code && a.text == b.text;
}
inline bool operator==(const ByeMsg&, const ByeMsg&) {
    return true;
}
inline bool operator==(const DecodeRateMsg& a, const DecodeRateMsg& b) {
    return std::equal(a.entries.begin(), a.entries.end(), b.entries.begin(), b.entries.end(),
                      [](const DecodeRateMsg::Entry& x, const DecodeRateMsg::Entry& y) {
                          return x.encoding == y.encoding && x.triangles == y.triangles &&
                                 x.seconds == y.seconds;
                      });
}

namespace remote_testing {

inline HelloMsg sample_hello() {
    return {7, "ct_head 256", "s3cret token", 3, SessionRole::none, ""};
}
// A hello that joins a shared session (version 2 on the wire).
inline HelloMsg sample_shared_hello() {
    return {7, "ct_head 256", "s3cret token", 3, SessionRole::follower, "class 3b"};
}
// A hello that takes exact values (version 3 on the wire), of a client of its own.
inline HelloMsg sample_exact_hello() {
    return {7, "ct_head 256", "s3cret token", 4, SessionRole::none, "", true};
}
inline SessionMsg sample_session() {
    return {"class 3b", "10.0.0.7:51234", 12};
}
inline ReadyMsg sample_ready() {
    // A volume turned a quarter about z: its x runs to the patient's back.
    return {{{-1, -2, -3}, {1, 2, 3}},
            -1024.5,
            3071.25,
            {256, 255, 113},
            {0.5f, 0.75f, 2},
            glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1))};
}
inline RequestMsg sample_request() {
    RequestMsg m;
    m.request_id = 0x0102030405060708;
    m.view.camera.eye = {1, -40, 3};
    m.view.camera.target = {0.5f, 0.25f, 0.125f};
    m.view.camera.up = {0, 0, 1};
    m.view.camera.projection = Projection::orthographic;
    m.view.camera.fovy_deg = 40;
    m.view.camera.ortho_height = 3;
    m.view.camera.near_z = 0.5f;
    m.view.camera.far_z = 90;
    m.view.frustum = {-0.5f, 0.75f, -0.25f, 0.5f, 0.5f, 90, Projection::orthographic};
    m.view.width = 800;
    m.view.height = 600;
    m.view.iso = 105.5;
    m.lod = LodSchedule::chosen;
    m.cached_groups = true;
    return m;
}
inline GroupKey sample_key(int i) {
    return {{4 + i, 5, 6 * i}, 2 + i % 3, 105.5, i % 2 == 0};
}
inline GroupMsg sample_group() {
    return {9,
            sample_key(0),
            true,
            0x0102030405060708,
            {std::byte{1}, std::byte{0}, std::byte{255}, std::byte{7}}};
}
inline VisibleMsg sample_visible() {
    return {9, {0, 2, 3, 9, 10}};  // a bitmap: 2 bytes of bits, 5 of deltas
}
inline EndOfFrameMsg sample_end_of_frame() {
    return {9, 480000, 120, 90000, 0x100000002};
}
inline ErrorMsg sample_error() {
    return {ErrorCode::unknown_dataset, "no dataset named \"ct_hed\""};
}

inline DecodeRateMsg sample_decode_rate() {
    return {{{3, 120000, 0.0125}, {4, 0x1000000001, 2.5}}};
}

inline ExactMsg sample_exact() {
    return {9, sample_key(1), {std::byte{0x5a}, std::byte{0}, std::byte{0x81}}};
}

inline std::vector<RemoteMessage> samples() {
    return {sample_hello(),   sample_ready(),        sample_request(), sample_group(),
            sample_visible(), sample_end_of_frame(), sample_error(),   ByeMsg{},
            sample_session(), sample_decode_rate(),  sample_exact()};
}

// decode_payload(type, bytes) throws a WireError naming the message and `field`.
inline void expect_view_wire_error(RemoteTag type, std::span<const std::byte> bytes,
                                   const std::string& field) {
    const std::string message = std::string(to_string(type)) + " message";
    try {
        decode_payload(type, bytes);
        ADD_FAILURE() << message << " decoded, expected a WireError naming " << field;
    } catch (const WireError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(message), std::string::npos) << what;
        EXPECT_NE(what.find(field), std::string::npos) << "expected " << field << " in: " << what;
    }
}

}  // namespace remote_testing
}  // namespace isowall::remote
