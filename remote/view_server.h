#pragma once
// `isowall serve`: the extraction server of remote viewing (the dissertation's chapter 4). It
// listens on TCP, and each connection gets two threads: a reader, which checks every message and
// raises the stop flag when a new request arrives (Figure 4.3: a request interrupts the current
// one at once), and a worker, which runs the connection's ServerSession on the latest request.
// Both see the connection as a MessageChannel, so a WebSocket (remote/http/, `serve --http`)
// handed to adopt() is served by the same code as a TCP connection.
//
// A connection begins with a hello within hello_timeout_s: protocol version, dataset, token
// (when the server has one; compared in constant time), group encoding; the server answers
// ready, or an error naming what was wrong and closes. Any message that does not decode, a
// frame over the payload limit, another version, a message a client may not send, or a request
// it cannot draw (request_checks.h: a frustum that cannot be drawn, an isovalue outside the
// volume's range) gets an error and a closed connection; other connections go on.
//
// After the hello, a connection on which nothing moves for idle_timeout_s (no message from the
// client, none sent to it) gets an error naming the limit and is closed: clients that said hello
// and then nothing used to hold every slot of max_clients for good. A client that stops reading
// what it asked for counts as idle too (the server's send cannot finish). An error, and the stop
// of a worker, may take 2 s: past that the connection is shut down (an error to a client that
// does not read, a worker blocked in a send to it), so no connection holds its threads for good.
// When a client has left, its memory goes back to the system (malloc_trim).
//
// Memory per connection: the reader's frame buffer (a header and at most max_payload_bytes,
// which a client's messages never need: a request is under 200 bytes), one visited-cell bitset
// per level of detail in use (1 bit per cell: 1.7 MiB for a 256 x 256 x 209 volume) with a hash
// of the visited cells' group ids, and with caching, each sent group's key and cells (12 bytes a
// cell). The octree is shared by every connection.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "extract/surface_extractor.h"
#include "remote/message_channel.h"
#include "remote/server_session.h"
#include "remote/shared_session.h"

namespace isowall::remote {

// Equal tokens, in time that does not depend on where they differ.
bool same_token(const std::string& a, const std::string& b);

struct Dataset {
    std::string name;  // what a hello names
    std::unique_ptr<Volume> volume;
    std::unique_ptr<SurfaceExtractor> extractor;  // the prototype each session shares
};

struct ServerOptions {
    std::string address = "127.0.0.1";
    int port = 7878;    // 0: any free port (see ViewServer::port)
    std::string token;  // empty: none asked for (only allowed on a loopback address)
    // The TCP protocol over TLS with this server context; null: plain TCP (loopback only).
    std::shared_ptr<const TlsContext> tls;
    // Names the page's Host header may carry besides those served_host_names finds (--allow-host:
    // a name the machine is reached by that it does not know, e.g. behind a proxy).
    std::vector<std::string> allowed_hosts;
    double rate_bits_per_s = 0;  // 0: as fast as the link goes; else paced (token bucket)
    int max_clients = 8;         // seated clients (past their hello), both kinds
    // Connections that have not said their hello yet (a TLS handshake, the hello itself); past
    // it the oldest is closed. Each waits at most hello_timeout_s anyway.
    int max_before_hello = 16;
    double hello_timeout_s = 10;
    // After the hello: nothing received and nothing sent for this long closes the connection.
    // A message that takes longer than this to go out (a 32 MiB group on a link under 1 Mbit/s
    // at the default) counts as nothing sent.
    double idle_timeout_s = 300;
    std::uint32_t max_payload_bytes = 1 << 16;  // what a client's message may be
    SessionOptions session;                     // the encoding comes from each hello
    SessionLimits sessions;                     // shared sessions (view --present, --follow)
    bool verbose = true;                        // a line per connection and request
};

// Why serving on `o.address` would expose it ("" when it may go on): anything but loopback
// needs TLS and a token. For InputError("--listen", "address", ...); `what` is "listening"
// or "serving the page".
std::string exposure_problem(const ServerOptions& o, const std::string& what);

// The names a page may reach the server by (its Host header), besides IP addresses and
// localhost: the listen address when it is a name, this machine's host name, the TLS
// certificate's DNS names and `allowed_hosts`. Any other name is a page of another site that
// made its own name resolve here (DNS rebinding), refused by the HTTP server.
std::vector<std::string> served_host_names(const ServerOptions& o);

class ViewServer {
  public:
    // Opens the listening socket at once (an address in use fails here).
    ViewServer(std::vector<Dataset> datasets, ServerOptions options);
    ~ViewServer();  // stops and joins every connection
    ViewServer(const ViewServer&) = delete;
    ViewServer& operator=(const ViewServer&) = delete;

    int port() const;
    // Accepts connections until `stop` reads true (checked every 100 ms).
    void serve(const std::atomic<bool>& stop);
    // Serves a connection that arrived another way (a WebSocket) with its own reader and worker
    // threads, as serve() does each TCP one; max_clients counts both kinds. Any thread may call
    // it. Seats (max_clients) are taken at the hello: when every seat is taken, the plain client
    // idle the longest between frames yields its seat and is told why; only when none can (all
    // in a frame or in a shared session) is the newcomer told the server is busy. Of the
    // connections that have not said their hello, at most max_before_hello stay: past it the
    // oldest is closed.
    void adopt(std::unique_ptr<MessageChannel> channel);
    // The datasets' names, in the order they were loaded.
    std::vector<std::string> dataset_names() const;
    const ServerOptions& options() const { return options_; }
    // Connections accepted so far (both kinds), and those open now.
    int accepted() const { return accepted_.load(); }
    int open_connections() const { return open_.load(); }
    const SessionHub& sessions() const { return hub_; }

  private:
    class Client;
    void reap(bool all);
    // The seat of a client whose hello was accepted: "" when it has one (given up by the idlest
    // other client if need be), else why not.
    std::string take_seat(Client& c);
    void leave(Client& c);  // a client's end: its seat and its count go back

    std::vector<Dataset> datasets_;
    ServerOptions options_;
    SessionHub hub_{options_.sessions};
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::atomic<int> accepted_{0}, open_{0};
};

}  // namespace isowall::remote
