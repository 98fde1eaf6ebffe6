#pragma once
// The network side of `isowall view`: one connection to `isowall serve`, its hello, and requests
// whose messages go to ClientFrames (client_frames.h), which draws them. Used by the program and,
// in process, by the tests.
#include <chrono>
#include <memory>
#include <string>

#include "remote/client_frames.h"
#include "remote/group_codec.h"
#include "remote/net/connection.h"
#include "remote/net/tls.h"

namespace isowall::remote {

struct ClientHello {
    std::string host = "127.0.0.1";
    int port = 7878;
    std::string dataset = "phantom";
    std::string token;
    // TLS with this client context (the authorities trusted); null: plain TCP.
    std::shared_ptr<const TlsContext> tls;
    GroupEncoding encoding = GroupEncoding::compact_zstd;
    // The server chooses cells or compact+zstd per group for the link it sees
    // (remote/encoding_choice.h); `encoding` is then not sent, and the client (unless it
    // follows a session) reports what decoding costs it (DecodeRateMsg).
    bool adaptive = false;
    double connect_timeout_s = 10;
    // A shared session (remote/shared_session.h): present it, or follow it; none: a view of
    // one's own.
    SessionRole role = SessionRole::none;
    std::string session;
    // The client takes a cells group's gradient voxels to a step first and their exact values
    // after (ExactMsg; a shared session's members get every group exact); false: every group
    // exact in one message.
    bool takes_exact = true;
};

class ViewClient {
  public:
    // Connects, says hello and waits for ready: NetError when the server cannot be reached,
    // RemoteError when it refuses (the server's text), WireError when it speaks nonsense.
    ViewClient(Renderer& renderer, const ClientHello& hello);
    const ReadyMsg& ready() const { return ready_; }

    // Sends a request for `view`; the frame it starts interrupts the one in progress.
    void request(const FrameView& view, LodSchedule lod, bool cached_groups);
    // Receives until the current request's end of frame: the frame, measured. Throws NetError
    // when nothing arrives for `timeout_s`.
    const ClientFrameResult& wait_done(double timeout_s);
    // Receives for `seconds`, whether or not the frame ends first; true when it has ended.
    bool receive_for(double seconds);
    // A follower: receives until the next frame the presenter asked for has ended (its
    // request came from the server); nullptr when nothing arrives for `timeout_s`. Throws
    // RemoteError when the server drops it (a follower too slow for the session).
    const ClientFrameResult* next_frame(double timeout_s);
    // The latest SessionMsg of a shared session (its presenter and size), if one came.
    const std::optional<SessionMsg>& session() const { return session_; }
    bool frame_active() const { return active_; }
    ClientFrames& frames() { return frames_; }
    std::uint64_t bytes_received() const { return conn_->bytes_received(); }
    // Says bye and closes.
    void close();

  private:
    bool receive_one(double timeout_s);
    double now_s() const;

    ClientFrames frames_;
    std::unique_ptr<Connection> conn_;
    ReadyMsg ready_;
    std::optional<SessionMsg> session_;
    std::uint64_t next_id_ = 1;
    bool active_ = false;
    bool reports_ = false;  // the server chooses encodings: tell it what decoding costs here
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

}  // namespace isowall::remote
