#include "remote/encoding_choice.h"

#include <algorithm>

namespace isowall::remote {
namespace {

// A send shorter than this did not wait for the link: its bytes went into buffers.
constexpr double kBlockedS = 50e-6;

constexpr double kKeep = 1.0 - 1.0 / EncodingChooser::kWindow;

}  // namespace

double EncodingChooser::bytes_per_s() const {
    // The link's own progress where the connection shows it. Else the sends that waited: a
    // client that reads only as fast as it decodes makes them wait as a slow link would, so its
    // decoding seconds are taken off the waiting, and what is left is the link's.
    const double blocked_link_s = blocked_s_ - client_busy_s_;
    const double seen = link_rates_ > 0 && link_s_ > 0 ? link_bytes_ / link_s_
                        : blocked_link_s > 0           ? sent_bytes_ / blocked_link_s
                                                       : 0;
    if (link_cap_ <= 0) return seen;
    return seen > 0 ? std::min(seen, link_cap_) : link_cap_;
}

EncodingChooser::Stages EncodingChooser::stages(GroupEncoding e) const {
    const Estimate& s = slot(e);
    if (s.groups == 0) return {};
    const double rate = bytes_per_s();
    const double making = made_triangles_ > 0 ? making_s_ / made_triangles_ : 0;
    return {making + s.seconds / s.triangles, rate > 0 ? s.bytes / s.triangles / rate : 0.0,
            s.reports == 0
                ? 0
                : *std::min_element(s.decoded.begin(),
                                    s.decoded.begin() + static_cast<std::ptrdiff_t>(
                                                            std::min(s.reports, kReportsKept)))};
}

double EncodingChooser::cost_per_triangle(GroupEncoding e) const {
    const Stages s = stages(e);
    return std::max({s.server, s.link, s.client});
}

bool EncodingChooser::probing() const {
    // The link is unknown until two sends waited (the first one's rate says little), or until
    // kProbeSends went with none waiting (buffers absorb them: a fast link), or the link was
    // found empty as kDrainedToKnow groups in a row were ready.
    if (link_rates_ >= kRatesToKnow || drained_in_row_ >= kDrainedToKnow) return false;
    if (same_host_ && blocked_sends_ == 0) return false;
    if (blocked_sends_ > 0) return blocked_sends_ < 2;
    return cells_.sends + compact_.sends < kProbeSends;
}

void EncodingChooser::ready_to_send(std::optional<LinkProgress> link, double now_s) {
    if (!link) return;
    same_host_ = link->same_host;
    // A peer on this host has no link between: its bytes on their way wait for the host's CPUs
    // (on 2 loaded cores the page's were held for 60 ms at a time, and read as a 2-10 MB/s link
    // they put the server into cells the page decodes slowly). Its sends' waits still count.
    if (last_link_ && !link->same_host && link->unacked >= kBacklogBytes && now_s > last_link_s_ &&
        link->acked >= last_link_->acked) {
        // A backlog on its way now: the link was busy since the last look (the one send since
        // then went right after it), and what it delivered meanwhile is its rate. A few bytes
        // unacknowledged say nothing: a receiver delays its acknowledgement of the last segment
        // up to 40 ms, and read as a backlog that made a 10 Gbit/s veth a 0.5 MB/s link (the
        // groups' own pace, 3 KB every 5 ms). The time the client's receive window held the
        // bytes back is left out: a client that does not read as fast as the link brings them
        // (a page busy decoding) is the client's stage, not the link's.
        const double busy_s = (now_s - last_link_s_) -
                              std::max(0.0, link->receiver_held_s - last_link_->receiver_held_s);
        if (busy_s > 0.25 * (now_s - last_link_s_)) {
            constexpr double keep = 1.0 - 1.0 / (4 * kWindow);
            link_bytes_ = link_bytes_ * keep + static_cast<double>(link->acked - last_link_->acked);
            link_s_ = link_s_ * keep + busy_s;
            ++link_rates_;
        }
    }
    // The link is empty and took bytes since the last look: it keeps up, whatever waits on this
    // side for a thread to write it (a WebSocket's io thread on a loaded host).
    const bool took = last_link_ && link->acked > last_link_->acked;
    if (cells_.sends + compact_.sends > 0)
        drained_in_row_ =
            link->unacked == 0 && (link->queued == 0 || took) ? drained_in_row_ + 1 : 0;
    last_link_ = link;
    last_link_s_ = now_s;
}

bool EncodingChooser::steps_pay() const {
    const double rate = bytes_per_s();
    if (rate <= 0) return probing();
    if (cells_.groups == 0) return rate < kCellsPayBelow;
    const Stages s = stages(GroupEncoding::cells);
    return s.link > std::max(s.server, s.client);
}

GroupEncoding EncodingChooser::best() const {
    // While the link is unknown: cells, fewer bytes.
    if (probing() && link_cap_ <= 0) return GroupEncoding::cells;
    // Cells cannot pay on a link known to be fast: they are not even measured (wants_measure).
    if (cells_.groups == 0 && fast_link()) return GroupEncoding::compact_zstd;
    // Nothing to weigh yet (the session measures both with the first group, after sending it):
    // on a link the server paces itself, the prior decides; else cells. Then the one not yet
    // measured, once, if only sending it can measure it.
    if (cells_.groups == 0 && compact_.groups == 0)
        return link_cap_ > 0 && link_cap_ >= kCellsPayBelow ? GroupEncoding::compact_zstd
                                                            : GroupEncoding::cells;
    if (cells_.groups == 0) return GroupEncoding::cells;
    if (compact_.groups == 0) return GroupEncoding::compact_zstd;
    return cost_per_triangle(GroupEncoding::cells) <= cost_per_triangle(GroupEncoding::compact_zstd)
               ? GroupEncoding::cells
               : GroupEncoding::compact_zstd;
}

GroupEncoding EncodingChooser::next(double now_s) {
    const GroupEncoding b = best();
    const GroupEncoding other =
        b == GroupEncoding::cells ? GroupEncoding::compact_zstd : GroupEncoding::cells;
    if (slot(other).groups == 0) return b;  // still measuring the first of each
    const double mine = cost_per_triangle(b), theirs = cost_per_triangle(other);
    const double dearer =
        mine > 0 ? std::clamp(theirs / mine, 1.0, kExploreDearest) : kExploreDearest;
    if (++since_explored_ < static_cast<std::uint64_t>(static_cast<double>(kExploreEvery) * dearer))
        return b;
    if (now_s >= 0 && explored_s_ >= 0 && now_s - explored_s_ < kExploreGapS) return b;
    since_explored_ = 0;
    if (now_s >= 0) explored_s_ = now_s;
    return other;
}

void EncodingChooser::encoded(GroupEncoding e, std::size_t triangles, std::size_t bytes,
                              double seconds, double making_seconds) {
    if (triangles == 0) return;
    Estimate& s = slot(e);
    ++s.groups;
    s.triangles = s.triangles * kKeep + static_cast<double>(triangles);
    s.seconds = s.seconds * kKeep + seconds;
    s.bytes = s.bytes * kKeep + static_cast<double>(bytes);
    made_triangles_ = made_triangles_ * kKeep + static_cast<double>(triangles);
    making_s_ = making_s_ * kKeep + making_seconds;
}

void EncodingChooser::sent(GroupEncoding e, std::size_t bytes, double seconds, bool waited) {
    // Decayed sums: the recent sends weigh most, so a link that changes is followed.
    constexpr double keep = 1.0 - 1.0 / (4 * kWindow);
    ++slot(e).sends;
    sent_bytes_ *= keep;
    blocked_s_ *= keep;
    client_busy_s_ *= keep;
    if (!waited || seconds < kBlockedS) return;
    // The first send that waits finds the buffers (a socket's, a paced link's burst) part full
    // and waits for part of its bytes only: counted, it made a 1 Mbit/s link look 130 MB/s.
    if (++blocked_sends_ == 1) return;
    sent_bytes_ += static_cast<double>(bytes);
    blocked_s_ += seconds;
}

void EncodingChooser::decoded(GroupEncoding e, std::uint64_t triangles, double seconds) {
    if (!(seconds >= 0)) return;
    // Only once the sends waited: before, the client's decoding held nothing back.
    if (blocked_sends_ > 1) client_busy_s_ += seconds;
    if (e != GroupEncoding::cells && e != GroupEncoding::compact_zstd) return;
    if (triangles == 0) return;
    Estimate& s = slot(e);
    // A report of a few triangles is all overhead and clock grain (0 ms for 84 triangles).
    if (triangles < kReportTriangles || seconds <= 0) return;
    s.decoded[s.reports++ % kReportsKept] = seconds / static_cast<double>(triangles);
}

}  // namespace isowall::remote
