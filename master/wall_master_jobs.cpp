// The wall master's side of the screen-region scheduler: handing out jobs (master/job_board.h)
// in the dispatch order (master/dispatch_order.h) and taking their ends and landings.
#include <algorithm>
#include <string>

#include "core/error.h"
#include "master/wall_master.h"

namespace isowall {

void WallMaster::fill(int rank) {
    while (auto id = board_->next_for(rank)) {
        const BoardJob& j = board_->job(*id);
        JobMsg m;
        m.generation = generation_;
        m.job = *id;
        m.owner = j.owner;
        m.band = j.band;
        m.view = tiles_[static_cast<std::size_t>(j.owner)].view;
        m.rect = j.rect;
        send_message(comm_, rank, m);
        if (j.owner != rank) raise_test_signal(o_.fault, FaultMoment::migration);
    }
}

void WallMaster::dispatch() {
    while (auto rank = order_.next()) {
        fill(*rank);
        order_.served(*rank, board_->in_hand(*rank) > 0);
    }
}

void WallMaster::handle_job(int from, const Message& m) {
    const std::uint64_t generation = std::visit(
        [](const auto& msg) -> std::uint64_t {
            if constexpr (requires { msg.generation; }) return msg.generation;
            return 0;
        },
        m);
    if (generation != generation_ || !board_) return;  // an interrupted frame's
    const std::uint32_t id = std::holds_alternative<JobDoneMsg>(m) ? std::get<JobDoneMsg>(m).job
                                                                   : std::get<LandedMsg>(m).job;
    if (id >= board_->size())
        throw WireError(rank_label(spec_, from) + ": no job " + std::to_string(id) +
                        " in this frame");
    const BoardJob& j = board_->job(id);
    if (auto* d = std::get_if<JobDoneMsg>(&m)) {
        if (j.worker != from || j.state != BoardJob::State::running)
            throw WireError(rank_label(spec_, from) + ": job " + std::to_string(id) +
                            " was not running on it");
        board_->done(id, d->cpu_s);
        if (j.owner != from) migrations_.push_back({j.owner, from, d->start_s, d->end_s, d->bytes});
        order_.clock(from, d->cpu_end_s);
        const auto r = static_cast<std::size_t>(from);
        frame_busy_s_.at(r) += d->cpu_s;
        frame_clock_s_.at(r) = std::max(frame_clock_s_.at(r), d->cpu_end_s);
        order_.ask(from);
        dispatch();
    } else {
        if (j.owner != from || j.worker == from || j.arrived || j.state == BoardJob::State::queued)
            throw WireError(rank_label(spec_, from) + ": landed job " + std::to_string(id) +
                            ", which no helper ran for it");
        board_->landed(id);
    }
    ask_curves();
}

void WallMaster::ask_curves() {
    if (!o_.measure || curves_asked_ || !board_ || !board_->complete()) return;
    curves_asked_ = true;
    for (int rank = 1; rank < comm_.size(); ++rank)
        send_message(comm_, rank, CurveAskMsg{generation_});
}

FrameFigures WallMaster::frame_figures() const {
    FrameFigures f;
    if (!board_) return f;
    f.jobs = board_->size();
    for (std::uint32_t id = 0; id < board_->size(); ++id)
        if (board_->job(id).state == BoardJob::State::done) ++f.jobs_done;
    f.migrated = migrations_.size();
    double sum = 0, most = 0;
    for (std::size_t r = 1; r < frame_busy_s_.size(); ++r) {
        sum += frame_busy_s_[r];
        most = std::max(most, frame_busy_s_[r]);
        f.emulated_s = std::max(f.emulated_s, frame_clock_s_[r]);
    }
    const std::size_t ranks = frame_busy_s_.size() > 1 ? frame_busy_s_.size() - 1 : 1;
    if (most > 0) f.balance = sum / static_cast<double>(ranks) / most;
    if (curves_in()) f.c99_s = time_to(wall_curve(frame_curves_), 0.99, false);
    return f;
}

bool WallMaster::curves_in() const {
    bool all = curves_asked_;
    for (std::size_t r = 1; r < frame_curves_.size(); ++r) all = all && frame_curves_[r].frames;
    return all;
}

}  // namespace isowall
