#include "comm/host_slots.h"

#include <fcntl.h>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace isowall {
namespace {

// How often a rank waiting for a slot looks at its stop flag.
constexpr long kPollNs = 20'000'000;

std::string system_error(const std::string& call, const std::string& name) {
    return call + "(" + name + "): " + std::strerror(errno);
}

}  // namespace

HostSlots::HostSlots(const std::string& job, int slots) : name_("/isowall-slots-" + job) {
    if (slots < 1)
        throw std::runtime_error("host slots: expected at least 1, got " + std::to_string(slots));
    sem_ = ::sem_open(name_.c_str(), O_CREAT, 0600, static_cast<unsigned>(slots));
    if (sem_ == SEM_FAILED) {
        sem_ = nullptr;
        throw std::runtime_error("host slots: " + system_error("sem_open", name_));
    }
}

HostSlots::~HostSlots() {
    if (sem_) ::sem_close(sem_);
}

bool HostSlots::acquire(const std::atomic<bool>& stop) {
    for (;;) {
        if (stop.load(std::memory_order_relaxed)) return false;
        timespec until{};
        ::clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += kPollNs;
        if (until.tv_nsec >= 1'000'000'000) {
            until.tv_sec += 1;
            until.tv_nsec -= 1'000'000'000;
        }
        if (::sem_timedwait(sem_, &until) == 0) return true;
        if (errno != ETIMEDOUT && errno != EINTR)
            throw std::runtime_error("host slots: " + system_error("sem_timedwait", name_));
    }
}

void HostSlots::release() {
    if (::sem_post(sem_) != 0)
        throw std::runtime_error("host slots: " + system_error("sem_post", name_));
}

int HostSlots::free_slots() const {
    int value = 0;
    ::sem_getvalue(sem_, &value);
    return value;
}

bool HostSlots::unlink() noexcept {
    return ::sem_unlink(name_.c_str()) == 0 || errno == ENOENT;
}

}  // namespace isowall
