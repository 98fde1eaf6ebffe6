#pragma once
// The decoders of the scheduler's messages (wall_protocol/protocol_jobs.cpp), for decode_message
// only: callers decode through decode_message, which picks one by tag.
#include <cstddef>
#include <span>

#include "wall_protocol/protocol.h"

namespace isowall::job_wire {

ReleaseMsg decode_release(std::span<const std::byte> bytes);
LostMsg decode_lost(std::span<const std::byte> bytes);
StartMsg decode_start(std::span<const std::byte> bytes);
AliveMsg decode_alive(std::span<const std::byte> bytes);
JobMsg decode_job(std::span<const std::byte> bytes);
JobDoneMsg decode_job_done(std::span<const std::byte> bytes);
RegionMsg decode_region(std::span<const std::byte> bytes);
LandedMsg decode_landed(std::span<const std::byte> bytes);
CurveAskMsg decode_curve_ask(std::span<const std::byte> bytes);
CurveMsg decode_curve(std::span<const std::byte> bytes);

// A correctness curve's points, as tile_result and curve carry them (protocol.cpp).
void put_curve(MessageWriter& w, const std::vector<CurvePoint>& curve);
std::vector<CurvePoint> get_curve(MessageReader& r);

}  // namespace isowall::job_wire
