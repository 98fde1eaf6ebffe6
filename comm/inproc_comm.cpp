#include "comm/inproc_comm.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

namespace isowall {

class InProcComm final : public Comm {
  public:
    InProcComm(InProcWorld& world, int rank) : world_(world), rank_(rank) {}
    int rank() const override { return rank_; }
    int size() const override { return world_.size(); }
    std::string host() const override { return "inproc"; }
    int ranks_on_host() const override { return world_.size(); }  // one process, one machine
    std::string job_id() const override { return world_.id(); }
    bool owns_process() const override { return false; }
    void send(int dest, Tag tag, std::span<const std::byte> bytes) override {
        world_.post(dest, Envelope{rank_, tag, std::vector<std::byte>(bytes.begin(), bytes.end())});
    }
    void send(int dest, Tag tag, std::vector<std::byte>&& bytes) override {
        world_.post(dest, Envelope{rank_, tag, std::move(bytes)});
    }
    std::optional<Envelope> receive(int source, double timeout_s) override {
        return world_.take(rank_, source, timeout_s);
    }
    void barrier() override { world_.barrier(); }
    [[noreturn]] void abort(int code) override { world_.abort(code); }

  private:
    InProcWorld& world_;
    int rank_;
};

InProcWorld::InProcWorld(int size) : mailboxes_(static_cast<std::size_t>(size)) {
    static std::atomic<std::uint64_t> worlds{0};
    id_ = "inproc-" + std::to_string(::getpid()) + "-" + std::to_string(worlds++);
}

std::unique_ptr<Comm> InProcWorld::comm(int rank) {
    return std::make_unique<InProcComm>(*this, rank);
}

std::optional<int> InProcWorld::aborted() const {
    std::lock_guard lock(mutex_);
    return abort_code_;
}

void InProcWorld::throw_if_aborted() const {
    if (abort_code_) throw CommAborted(*abort_code_);
}

void InProcWorld::post(int dest, Envelope e) {
    if (dest < 0 || dest >= size())
        throw std::runtime_error("inproc: send to rank " + std::to_string(dest));
    std::lock_guard lock(mutex_);
    throw_if_aborted();
    mailboxes_[static_cast<std::size_t>(dest)].messages.push_back(std::move(e));
    changed_.notify_all();
}

std::optional<Envelope> InProcWorld::take(int rank, int source, double timeout_s) {
    std::unique_lock lock(mutex_);
    auto& box = mailboxes_[static_cast<std::size_t>(rank)].messages;
    std::optional<Envelope> found;
    auto ready = [&] {
        if (abort_code_) return true;
        for (auto it = box.begin(); it != box.end(); ++it)
            if (source < 0 || it->from == source) {  // first in order from that source: MPI's rule
                found = std::move(*it);
                box.erase(it);
                return true;
            }
        return false;
    };
    if (timeout_s == kForever) {
        changed_.wait(lock, ready);
    } else {
        const auto until = std::chrono::steady_clock::now() +
                           std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(std::max(timeout_s, 0.0)));
        changed_.wait_until(lock, until, ready);
    }
    throw_if_aborted();
    return found;
}

void InProcWorld::barrier() {
    std::unique_lock lock(mutex_);
    throw_if_aborted();
    const std::uint64_t round = barrier_round_;
    if (++barrier_waiting_ == size()) {
        barrier_waiting_ = 0;
        ++barrier_round_;
        changed_.notify_all();
        return;
    }
    changed_.wait(lock, [&] { return abort_code_ || barrier_round_ != round; });
    throw_if_aborted();
}

void InProcWorld::abort(int code) {
    {
        std::lock_guard lock(mutex_);
        if (!abort_code_) abort_code_ = code;
        changed_.notify_all();
    }
    throw CommAborted(code);
}

std::vector<int> run_in_process(int ranks, const std::function<int(Comm&)>& fn) {
    InProcWorld world(ranks);
    std::vector<int> codes(static_cast<std::size_t>(ranks), 0);
    std::vector<std::thread> threads;
    for (int r = 0; r < ranks; ++r)
        threads.emplace_back([&, r] {
            auto comm = world.comm(r);
            int& code = codes[static_cast<std::size_t>(r)];
            try {
                code = fn(*comm);
            } catch (const CommAborted& e) {
                code = e.code();
            } catch (const std::exception& e) {
                std::fprintf(stderr, "inproc: rank %d: uncaught: %s\n", r, e.what());
                code = 1;
                try {
                    comm->abort(1);
                } catch (const CommAborted&) {
                }
            }
        });
    for (auto& t : threads) t.join();
    return codes;
}

}  // namespace isowall
