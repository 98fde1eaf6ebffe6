#pragma once
// `isowall serve` and `isowall view`: their options, command lines and runs.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/engine_cli.h"

namespace isowall {
namespace remote {
class TlsContext;
}

// The port `isowall serve` listens on when the command line names none.
inline constexpr int kServePort = 7878;

struct ServeCommand {
    std::vector<std::string>
        datasets;  // NAME=PATH (any format --volume reads); "phantom" is always offered
    std::string listen = "127.0.0.1";
    int port = -1;       // --port; -1: not given (the port in --listen, else kServePort)
    int http_port = -1;  // --http: the page and WebSocket on this port (0: any free); -1: none
    std::string token;
    std::string tls_cert, tls_key;         // PEM files; both or neither (TLS on every port)
    std::vector<std::string> allow_hosts;  // --allow-host: more names the page may be reached by
    double rate_mbps = 0;
    int max_clients = 8;
    // Shared sessions (remote/shared_session.h): how many, members each, a follower's queue.
    int max_sessions = 16, session_members = 32;
    double follower_queue_mib = 64;
    double idle_timeout_s = 300;  // --idle-timeout: a connection idle this long after its hello
    double lod_rays_percent = 0.25;
    std::string cache_dir;
    // Its max count is remote viewing's own (kServeMaxCount), chosen on the bytes a client needs.
    EngineCli engine = serve_engine_defaults();
    bool quiet = false;
};

struct ViewCommand {
    std::string connect = "127.0.0.1:7878";
    std::string dataset = "phantom";
    std::string token;
    bool tls = false;    // --tls: TLS, the server's certificate checked against the system's CAs
    std::string tls_ca;  // --tls-ca: TLS, trusting the authorities in this PEM file
    int test_case = 0;   // 1-7: the study's cases; 0: the options below
    std::string encoding = "auto";
    bool lod = false, no_lod = false, cache = false;
    bool exact_only = false;  // --exact-only: no cells group to a step first (ExactMsg)
    std::optional<double> iso;
    std::string size = "800x600";
    std::vector<double> orbit;
    double zoom = 1.0;
    std::string script;
    std::string out = "view.png";
    std::string timeline;
    std::string gl = "osmesa";
    double timeout_s = 120;
    bool quiet = false;
    // Shared sessions (remote/shared_session.h): present this view as session NAME, or follow
    // session NAME (every view its presenter asks for; --out after each frame, --frames of them).
    std::string present, follow;
    int frames = 0;  // with --follow: end after this many frames; 0: when the connection ends
};

// --tls-cert and --tls-key of serve and wall: both or neither (InputError naming the one given);
// null when neither.
// --allow-host NAME (repeatable): a name the page is reached by besides its addresses, localhost,
// the listen name, this machine's name and the certificate's (remote::served_host_names); each
// checked as a host name. `page` names the option that serves the page.
void add_allow_host_option(CLI::App& cmd, std::vector<std::string>& names, const char* page);

std::shared_ptr<const remote::TlsContext> server_tls(const std::string& cert,
                                                     const std::string& key);

CLI::App* add_serve_command(CLI::App& app, ServeCommand& o);
CLI::App* add_view_command(CLI::App& app, ViewCommand& o);
int run_serve(const ServeCommand& o);
int run_view(const ViewCommand& o);

}  // namespace isowall
