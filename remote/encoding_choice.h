#pragma once
// Which encoding a server sends the next group in, when the client lets it choose (the
// dissertation's 5.2.3: tune compression to whichever of server and network is the bottleneck).
// `cells` sends about a quarter of compact+zstd's bytes and costs several times its CPU a
// triangle; which brings the picture sooner depends on the link. The chooser keeps, for each of
// the two, a running mean of the server's seconds a triangle (encoding), of bytes a triangle and
// of the client's seconds a triangle decoding (its DecodeRateMsg reports); for both, the seconds
// a triangle the server spent making groups (extraction); and the link's rate: bytes over the
// seconds the sends blocked. A group goes in the encoding whose time a triangle is the smaller,
// taken as the slowest of three stages that overlap: the server (extraction and encoding), the
// link (bytes over the rate) and the client (decoding). While sends return at once (buffers
// absorb them), bytes cost no time and the cheaper encoding wins.
// The rate is the link's, one for both encodings: a paced link's send waits for the bytes sent
// before it, so a rate kept per encoding charged a cells group for the compact+zstd group ahead
// of it. The client's decoding counts through its reports: through the sends alone it showed only
// once the socket buffers between the two were full (megabytes on a fast link), so the server
// kept sending cells to a client that decoded them ten times slower than compact+zstd. A group in
// the encoding not chosen goes out every kExploreEvery groups times how many times dearer it was
// (at most kExploreDearest), so both estimates follow the surface and the machine without a slow
// link paying much for the exploring. Pure: no clock, no I/O; the session measures and reports.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "remote/group_codec.h"

namespace isowall::remote {

// How far a connection's link has taken what was sent: bytes still queued on this side (not yet
// written to the socket), bytes the peer's host acknowledged in all, and bytes written but not
// yet acknowledged (remote/net/tcp_progress.h).
struct LinkProgress {
    std::size_t queued = 0;
    std::uint64_t acked = 0;
    std::size_t unacked = 0;
    double receiver_held_s = 0;  // in all, the seconds the peer's receive window held sends back
    bool same_host = false;      // no network between the ends: no rate is read from progress
};

// The hello's encoding value for "the server chooses per group" (not a codec's id).
inline constexpr std::uint8_t kAdaptiveEncoding = 255;
// A hello may ask for a codec's id or kAdaptiveEncoding.
inline bool known_hello_encoding(std::uint8_t e) {
    return e <= static_cast<std::uint8_t>(GroupEncoding::cells) || e == kAdaptiveEncoding;
}
// What a known hello encoding means for a session: one encoding, or the chooser's.
inline void apply_hello_encoding(std::uint8_t e, GroupEncoding& encoding, bool& adaptive) {
    adaptive = e == kAdaptiveEncoding;
    encoding = adaptive ? GroupEncoding::cells : static_cast<GroupEncoding>(e);
}

// The one of cells and compact+zstd that `e` is not.
inline GroupEncoding other_encoding(GroupEncoding e) {
    return e == GroupEncoding::cells ? GroupEncoding::compact_zstd : GroupEncoding::cells;
}

class EncodingChooser {
  public:
    static constexpr std::uint64_t kExploreEvery = 16;
    // Exploring costs a sixteenth of the chosen encoding's time up to this ratio, more beyond.
    // A page decodes cells 10-30x slower than compact+zstd; with 8 here the groups explored in
    // cells cost it about a tenth of its frame's main-thread time on a fast link. The link is
    // measured on whichever encoding goes, so a link that slows is followed without exploring.
    static constexpr double kExploreDearest = 32;
    // ...and at most once in this many seconds. Where both encodings' stages are the server's
    // (a fast link), cells look only 1.5x dearer and went out every 24 groups: 3-9 of each of
    // the head's frames, which a page decodes at 3-10 ms each against 1 for compact+zstd. What
    // exploring refreshes (the other encoding's costs, the client's decoding of it) changes over
    // seconds, not groups; the link is measured on whichever encoding goes.
    static constexpr double kExploreGapS = 1.0;
    // The client's decoding of an encoding is the fastest of its last this many reports: what it
    // can do. A report that covers a stall says little of the encoding: the page's first
    // compact+zstd report, its decoders cold and the machine loaded, read 6 us a triangle (0.3 once
    // warm), and set against cells' 3.5 it sent 171 of 180 groups as cells.
    static constexpr std::size_t kReportsKept = 4;
    static constexpr std::uint64_t kReportTriangles = 500;  // fewer: the report is left out
    // The estimates are ratios of decayed sums (seconds or bytes over triangles), which weigh
    // the last this many groups most and each group by its triangles: a pass of a few triangles
    // (its header, the time to find it) says little of the next thousand.
    static constexpr double kWindow = 16;

    // The link is no faster than this (the server's own pacing, `serve --rate-mbps`): the rate
    // until one is seen, and the most one may be. Without it the link is probed (kProbeSends).
    void set_link_cap(double bytes_per_s) { link_cap_ = bytes_per_s; }
    // The encoding for the next group.
    // `now_s` (any steady clock; negative: none) spaces the exploring by kExploreGapS.
    GroupEncoding next(double now_s = -1);
    // Whether the session should encode a group it sent in the other encoding `e` too, after the
    // send, for the chooser alone: while `e` is unmeasured, so neither has to be sent to be known
    // and the measuring costs the group no time. Exploring by sending compact+zstd's first group
    // cost a slow link five times its bytes just when C climbs fastest (the 256 head at 1 Mbit/s:
    // C = 90% at 0.385 s against cells' 0.281); encoding both ways before the send put 8-25 ms on
    // the head's first group at 100 Mbit/s. Not cells on a link known to be fast (fast_link()):
    // there they cannot pay, and measuring them cost the engine's first groups 10-20% at
    // 100 Mbit/s; they are measured once the link is seen slower.
    bool wants_measure(GroupEncoding e) const {
        return slot(e).groups == 0 && !(e == GroupEncoding::cells && fast_link());
    }
    // The link is the server's own pacing at kCellsPayBelow or more, and no slower rate was seen;
    // or the peer is on this host, unpaced, and no send has waited (a tunnel to a far client
    // shows once its buffers fill and sends wait; until then bytes cost nothing, and cells cost
    // a page on this host 10-40 ms a group while its WebAssembly is cold).
    bool fast_link() const {
        return (same_host_ && link_cap_ <= 0 && blocked_sends_ == 0) ||
               (link_cap_ > 0 && bytes_per_s() >= kCellsPayBelow);
    }
    // The first group's encoding on a link the server paces (set_link_cap), before either is
    // measured: cells below this rate. A triangle costs about 6.5 bytes as compact+zstd and 1 as
    // cells; the stages overlap, and cells' slowest is about 1.1 us a triangle (the page's decoding
    // at 0.9 M triangles/s; the server makes and encodes them in about as much), compact+zstd's
    // about 0.7 (making and encoding): compact+zstd is sooner once 6.5 bytes take under 1.1 us,
    // about 6 MB/s. Measured figures replace this from the second group on.
    static constexpr double kCellsPayBelow = 5e6;
    // Groups go as cells (the smaller) while the link is unknown: until two sends have waited
    // for it, or this many went without any waiting (buffers absorb them: a fast link). A paced
    // link's burst and a socket's buffer make the first sends look fast (the 256 head at
    // 1 Mbit/s sent its fifth group as compact+zstd in some runs, 23.7 KB against 5.8).
    static constexpr std::uint64_t kProbeSends = 8;
    // ...or until this many groups in a row found every byte sent before them already at the
    // client's host as they were ready to go (ready_to_send): the link keeps up with the server,
    // whatever its rate, so bytes cost no time, and a far client on a fast link is spared the
    // rest of the probe's cells groups. A slow link still holds the group before (a 5 KB group
    // takes 40 ms at 1 Mbit/s; the engine makes the next in a few).
    static constexpr int kDrainedToKnow = 2;
    // ...or once the link's progress gave this many rates (ready_to_send).
    static constexpr int kRatesToKnow = 2;
    // A backlog: more bytes unacknowledged than a receiver's delayed acknowledgement leaves (a
    // segment or two), fewer than two groups hold on a slow link.
    static constexpr std::size_t kBacklogBytes = 8192;
    // As a group is ready to go (`now_s` on any steady clock): how far the link has taken what
    // was sent, or nullopt where the connection cannot tell. Where bytes are still on their way
    // (unacknowledged), the link was busy since the last look, and the bytes acknowledged
    // meanwhile over the seconds are its rate: measured so, a slow link shows from its second
    // group on, however many bytes the socket's buffers take before a send has to wait.
    void ready_to_send(std::optional<LinkProgress> link, double now_s);
    // What a group cost: its triangles, the bytes it encoded to, the server's seconds to encode it
    // and to make it (from the end of the previous send to the start of encoding).
    void encoded(GroupEncoding e, std::size_t triangles, std::size_t bytes, double seconds,
                 double making_seconds = 0);
    // One send of a group in `e`: its bytes on the wire, the seconds the call took, and whether
    // it waited (the thread blocked in it: voluntary_switches() moved). A send that took long
    // without waiting was the scheduler's doing, not the link's: on a loaded machine (the page,
    // its GPU process and the server on 2 cores) such sends made loopback look like 2 MB/s and
    // the server sent a fresh page 145 of the head's 180 groups as cells.
    void sent(GroupEncoding e, std::size_t bytes, double seconds, bool waited = true);
    // The client's report: it decoded `triangles` of groups in `e` in `seconds`. Encodings the
    // chooser does not pick between are ignored.
    void decoded(GroupEncoding e, std::uint64_t triangles, double seconds);

    // Seconds a triangle costs in `e` at the rate seen; 0 until `e` was measured.
    double cost_per_triangle(GroupEncoding e) const;
    // The link's bytes a second: from its progress (ready_to_send) where that gave a rate; else
    // from the sends that blocked for it, over the seconds they waited less those the client
    // reported decoding (a client that reads no faster than it decodes makes sends wait too,
    // and counted as the link's that waiting locked a busy page into cells, which it decodes ten
    // times slower); 0 while neither says anything, or the client's decoding accounts for all the
    // waiting. Never more than the server's own pacing (set_link_cap).
    double bytes_per_s() const;
    // Groups sent in `e`.
    std::uint64_t chosen(GroupEncoding e) const { return slot(e).sends; }
    // Whether a cells group's gradients' voxels should go to a step first, their exact values
    // after (cell_codec.h): where the link bounds cells (their bytes a triangle over the rate take
    // longer than the server's work and the client's decoding), fewer bytes first bring the
    // picture sooner; where the server or the client bounds them, a step brings nothing sooner
    // and costs a second decoding and 2-3% more bytes. While the link is unknown, yes (cells go
    // then for their fewer bytes); on one whose sends never waited, no (bytes cost no time);
    // before cells are measured, below kCellsPayBelow.
    bool steps_pay() const;

  private:
    struct Estimate {
        double triangles = 0, seconds = 0, bytes = 0;  // decayed sums over its groups
        std::uint64_t groups = 0, sends = 0;           // measured, sent
        double sent_bytes = 0, blocked_s = 0;          // decayed sums over the recent sends
        // The client's seconds a triangle in its last kReportsKept reports of this encoding.
        std::array<double, kReportsKept> decoded{};
        std::size_t reports = 0;
    };
    Estimate& slot(GroupEncoding e) { return e == GroupEncoding::cells ? cells_ : compact_; }
    const Estimate& slot(GroupEncoding e) const {
        return e == GroupEncoding::cells ? cells_ : compact_;
    }
    GroupEncoding best() const;
    // The three stages of a triangle in `e` that overlap, in seconds (0 where unknown): the
    // server's (making and encoding), the link's (its bytes at the rate seen) and the client's.
    struct Stages {
        double server = 0, link = 0, client = 0;
    };
    Stages stages(GroupEncoding e) const;
    // The link is unknown: fewer than two sends waited for it, fewer than kProbeSends went,
    // fewer than kDrainedToKnow groups in a row found it empty, and fewer than kRatesToKnow
    // rates came from its progress. Not probed at all to a peer on this host while no send
    // waited: its bytes go through the kernel's buffers, and 8 groups never fill them, so the
    // probe would end as one on a fast link does; only a send that waits shows a slow one (a
    // tunnel to a far client), then as on any link. On 2 loaded cores the page's first frame
    // decoded the probe's 8 cells groups in cold WebAssembly, 10 ms each.
    bool probing() const;

    Estimate cells_, compact_;
    double made_triangles_ = 0, making_s_ = 0;  // extraction, the same in either encoding
    double sent_bytes_ = 0, blocked_s_ = 0;     // decayed sums over the recent sends
    double client_busy_s_ = 0;                  // the client's decoding meanwhile (its reports)
    std::uint64_t blocked_sends_ = 0;           // sends that waited for the link
    int drained_in_row_ = 0;                    // groups that found the link empty (ready_to_send)
    std::optional<LinkProgress> last_link_;     // the last look at the link, and when
    double last_link_s_ = 0;
    double link_bytes_ = 0, link_s_ = 0;  // decayed sums of the link's busy progress
    int link_rates_ = 0;                  // rates read from the link's progress
    bool same_host_ = false;              // the peer is on this host (LinkProgress)
    double explored_s_ = -1;              // when the other encoding last went (next's clock)
    double link_cap_ = 0;                 // bytes a second; 0: none known
    std::uint64_t since_explored_ = 0;
};

}  // namespace isowall::remote
