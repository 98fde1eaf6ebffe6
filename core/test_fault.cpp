#include "core/test_fault.h"

#include <charconv>
#include <csignal>
#include <string>

namespace isowall {
namespace {

FaultMoment moment_of(std::string_view s) {
    if (s == "init") return FaultMoment::init;
    if (s == "load") return FaultMoment::load;
    if (s == "frame") return FaultMoment::frame;
    if (s == "migration") return FaultMoment::migration;
    if (s == "next") return FaultMoment::next;
    if (s == "gather") return FaultMoment::gather;
    if (s == "end") return FaultMoment::end;
    if (s == "slab") return FaultMoment::slab;
    return FaultMoment::none;
}

TestFault fault_of(std::string_view kind) {
    if (kind == "hang") return {FaultAction::hang};
    if (kind == "exit") return {FaultAction::exit};
    if (kind == "throw") return {FaultAction::throw_error};
    if (kind == "slow") return {FaultAction::slow};
    if (kind == "late") return {FaultAction::late};
    const auto at = kind.find('@');
    if (at == std::string_view::npos) return {};
    const FaultMoment moment = moment_of(kind.substr(at + 1));
    if (moment == FaultMoment::none) return {};
    if (kind.substr(0, at) == "stop") return {FaultAction::stop, moment};
    if (kind.substr(0, at) == "kill") return {FaultAction::kill, moment};
    if (kind.substr(0, at) == "term") return {FaultAction::term, moment};
    return {};
}

}  // namespace

TestFault parse_test_fault(const char* spec) {
    if (!spec) return {};
    const std::string_view s = spec;
    const auto colon = s.find(':');
    if (colon == std::string_view::npos) return {};
    TestFault f = fault_of(s.substr(0, colon));
    const std::string_view rank = s.substr(colon + 1);
    if (rank == "tiles") {
        f.rank = TestFault::kEveryTile;
        return f;
    }
    const auto r = std::from_chars(rank.data(), rank.data() + rank.size(), f.rank);
    if (f.action == FaultAction::none || r.ec != std::errc() || r.ptr != rank.data() + rank.size())
        return {};
    return f;
}

void raise_test_signal(const TestFault& fault, FaultMoment moment) {
    if (fault.moment != moment || moment == FaultMoment::none) return;
    if (fault.action == FaultAction::stop) ::raise(SIGSTOP);
    if (fault.action == FaultAction::kill) ::raise(SIGKILL);
    if (fault.action == FaultAction::term) ::raise(SIGTERM);
}

}  // namespace isowall
