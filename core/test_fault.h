#pragma once
// The fault tests' hook (ISOWALL_TEST_FAULT=KIND:RANK), parsed once where the program starts into
// a typed value; the wall's ranks only compare enums. KIND is one of
//   hang            a tile stops answering after its first view, until the job ends
//   exit            a tile ends its process at once (process only; never in process)
//   throw           a tile, or the master, throws an error after its first view
//   slow            a tile's engine stops for kSlowSampleS at every sample point, so that its
//                   frames last seconds whatever the machine (tests of what happens mid-frame)
//   late            a tile that finishes another tile's job of its first view tells the master,
//                   then holds the region result until a newer view reaches it, and sends it
//                   only then: a helper finishing an old view's job after the view changed
//   stop@MOMENT     the rank sends itself SIGSTOP at MOMENT, as an operator's `kill -STOP` would
//   kill@MOMENT     the same with SIGKILL
//   term@MOMENT     the same with SIGTERM, which the process may catch (import: a stop mid-way)
// MOMENT is init, load, frame, migration, next (a tile's second view as it comes: between frames
// when the script waited for the first), gather or end (a tile released, the master after its
// outputs), or slab (import: after its first slab of chunks). RANK is a rank, or "tiles" for
// every tile; a command that is not the wall is rank 0.
#include <cstdint>
#include <string_view>

namespace isowall {

enum class FaultAction : std::uint8_t {
    none,
    hang,
    exit,
    throw_error,
    slow,
    late,
    stop,
    kill,
    term
};
enum class FaultMoment : std::uint8_t {
    none,
    init,
    load,
    frame,
    migration,
    next,
    gather,
    end,
    slab
};

struct TestFault {
    FaultAction action = FaultAction::none;
    FaultMoment moment = FaultMoment::none;  // of stop and kill only
    int rank = -1;                           // the rank that fails, or kEveryTile
    static constexpr int kEveryTile = -2;
    static constexpr double kSlowSampleS = 0.02;

    // Whether the fault is on `rank` (the master is rank 0).
    bool on(int r) const { return rank == r || (rank == kEveryTile && r != 0); }
};

// "KIND:RANK" -> the fault; no fault (action none) when `spec` is null, empty or not of that form,
// as without the variable.
TestFault parse_test_fault(const char* spec);

// When `fault` is a stop, kill or term at `moment`, this process sends itself SIGSTOP, SIGKILL
// or SIGTERM.
// Anything else does nothing.
void raise_test_signal(const TestFault& fault, FaultMoment moment);

}  // namespace isowall
