// `isowall serve`: options, the datasets it loads, and the accept loop until SIGINT or SIGTERM.
#include <cstdio>
#include <optional>

#include "app/remote_commands.h"
#include "app/stop_signals.h"
#include "cli/cli_checks.h"
#include "cli/volume_options.h"
#include "core/error.h"
#include "core/number.h"
#include "remote/http/http_front.h"
#include "remote/net/endpoint.h"
#include "remote/view_server.h"
#include "volume/octree.h"

namespace isowall {
namespace {

remote::Dataset load_dataset(const std::string& name, const std::string& path,
                             const std::string& cache_dir) {
    VolumeOptions vo;
    vo.path = path;
    vo.cache_dir = cache_dir;
    OpenedVolume ov = open_volume(vo);
    remote::Dataset d;
    d.name = name;
    d.volume = std::make_unique<Volume>(std::move(ov.volume));
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    d.extractor = make_surface_extractor(*d.volume, src);
    std::printf("serve: dataset %s: values [%g, %g]\n", name.c_str(), d.extractor->value_min(),
                d.extractor->value_max());
    return d;
}

// --listen in the endpoint form of view --connect; a port given there and in --port is an error.
remote::Endpoint listen_endpoint(const ServeCommand& o) {
    remote::Endpoint at = remote::parse_listen_endpoint(o.listen, -1, "--listen", "endpoint");
    if (at.port >= 0 && o.port >= 0)
        throw InputError("--port", "value",
                         "the port is given twice: in --listen " + quote(o.listen) +
                             " and as --port " + std::to_string(o.port));
    if (at.port < 0) at.port = o.port >= 0 ? o.port : kServePort;
    return at;
}

}  // namespace

void add_allow_host_option(CLI::App& cmd, std::vector<std::string>& names, const char* page) {
    cmd.add_option("--allow-host", names,
                   std::string("A name the page (") + page +
                       ") may be reached by beyond its addresses, localhost, this machine's name "
                       "and the certificate's, e.g. behind a proxy; repeat for more. A page "
                       "reached by any other name is refused (a site of another owner may point "
                       "its own name here)")
        ->check([](const std::string& name) -> std::string {
            try {
                const remote::Endpoint e =
                    remote::parse_listen_endpoint(name, 0, "--allow-host", "name");
                if (e.port == 0 && e.host == name) return "";
            } catch (const InputError&) {
            }
            return "expected a host name without a port, got " + quote(name);
        });
}

std::shared_ptr<const remote::TlsContext> server_tls(const std::string& cert,
                                                     const std::string& key) {
    if (cert.empty() != key.empty())
        throw InputError(cert.empty() ? "--tls-key" : "--tls-cert", "value",
                         "TLS needs both --tls-cert and --tls-key");
    if (cert.empty()) return nullptr;
    return std::make_shared<const remote::TlsContext>(remote::TlsContext::server(cert, key));
}

CLI::App* add_serve_command(CLI::App& app, ServeCommand& o) {
    auto* c = app.add_subcommand(
        "serve",
        "Extraction server for remote viewing: streams the groups of each view a client "
        "asks for (see isowall view)");
    c->add_option("--dataset", o.datasets,
                  "Offer a volume as NAME=PATH (any format --volume reads); repeat for more. The "
                  "phantom is always "
                  "offered as 'phantom'");
    c->add_option("--listen", o.listen,
                  "Where to listen: HOST, HOST:PORT or [IPV6]:PORT, as view --connect takes it "
                  "(PORT 0: any free port, printed); anything but loopback needs TLS and --token")
        ->capture_default_str();
    c->add_option("--port", o.port,
                  "TCP port when --listen names none (default " + std::to_string(kServePort) +
                      "; 0: any free port, printed)")
        ->check(CLI::Range(0, 65535));
    c->add_option("--http", o.http_port,
                  "Also serve the browser page and the protocol over WebSocket (/ws) on this "
                  "port, at the --listen address (0: any free port, printed)")
        ->check(CLI::Range(0, 65535));
    c->add_option("--token", o.token, "A secret every client must present in its hello");
    c->add_option("--tls-cert", o.tls_cert,
                  "TLS on every port (the protocol, the page and its WebSocket): this PEM "
                  "certificate chain, with --tls-key");
    c->add_option("--tls-key", o.tls_key, "The PEM private key of --tls-cert (no passphrase)");
    add_allow_host_option(*c, o.allow_hosts, "--http");
    c->add_option("--rate-mbps", o.rate_mbps,
                  "Emulate a link of this many Mbit/s (token bucket on every send); 0: no limit")
        ->transform(number_in({0, 1e6}))
        ->capture_default_str();
    c->add_option("--max-clients", o.max_clients,
                  "Clients served at once (seats, taken at the hello). When every seat is "
                  "taken, the client idle the longest between frames gives its seat to the "
                  "newcomer and is told why")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    c->add_option("--max-sessions", o.max_sessions,
                  "Shared sessions (view --present NAME) open at once")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    c->add_option("--session-members", o.session_members,
                  "Members of one shared session, its presenter included")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    c->add_option("--follower-queue", o.follower_queue_mib,
                  "MiB of groups that may wait for one follower; a follower that falls further "
                  "behind is dropped with an error")
        ->transform(number_in({1, 65536}))
        ->capture_default_str();
    c->add_option("--idle-timeout", o.idle_timeout_s,
                  "Close a connection on which nothing was received or sent for this many "
                  "seconds after its hello, with an error naming the limit")
        ->transform(number_in(limits::kSeconds))
        ->capture_default_str();
    c->add_option("--lod-rays", o.lod_rays_percent,
                  "Progressive LOD: rays of each coarse LOD level, in percent of the view's pixels")
        ->transform(number_in({0, 100, true}))
        ->capture_default_str();
    c->add_option("--cache-dir", o.cache_dir, "Octree cache folder (default: beside the volume)");
    add_engine_options(*c, o.engine);
    c->add_flag("--quiet,-q", o.quiet, "No line per connection and request");
    return c;
}

int run_serve(const ServeCommand& o) {
    remote::ServerOptions so;
    const remote::Endpoint at = listen_endpoint(o);
    so.address = at.host;
    so.port = at.port;
    so.token = o.token;
    so.tls = server_tls(o.tls_cert, o.tls_key);
    so.allowed_hosts = o.allow_hosts;
    // Before the datasets load (a large one takes a while): ViewServer checks it again.
    if (std::string p = remote::exposure_problem(so, "listening"); !p.empty())
        throw InputError("--listen", "address", p);
    so.rate_bits_per_s = o.rate_mbps * 1e6;
    so.max_clients = o.max_clients;
    so.idle_timeout_s = o.idle_timeout_s;
    so.sessions.max_sessions = static_cast<std::size_t>(o.max_sessions);
    so.sessions.max_members = static_cast<std::size_t>(o.session_members);
    so.sessions.max_queue_bytes = static_cast<std::size_t>(o.follower_queue_mib * (1 << 20));
    so.verbose = !o.quiet;
    so.session.engine = to_engine_options(o.engine);
    so.session.lod_ray_share = o.lod_rays_percent / 100.0;
    std::vector<remote::Dataset> datasets;
    datasets.push_back(load_dataset("phantom", "", o.cache_dir));
    for (const std::string& spec : o.datasets) {
        const auto eq = spec.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
            throw InputError("--dataset", "value", "expected NAME=PATH, got " + quote(spec));
        const std::string name = spec.substr(0, eq);
        for (const remote::Dataset& d : datasets)
            if (d.name == name)
                throw InputError("--dataset", "value", "the name " + quote(name) + " is taken");
        datasets.push_back(load_dataset(name, spec.substr(eq + 1), o.cache_dir));
    }
    {
        remote::ViewServer server(std::move(datasets), so);
        // After the server, so it goes first: no WebSocket is handed to a server being
        // destroyed. A port in use throws here, and the TCP listener closes with `server`.
        std::optional<remote::HttpFrontEnd> http;
        if (o.http_port >= 0) http.emplace(server, o.http_port);
        catch_stop_signals();
        std::printf(
            "serve: listening on %s%s%s%s\n", remote::host_port(at.host, server.port()).c_str(),
            so.tls ? " (TLS)" : "", o.token.empty() ? "" : " (token required)",
            o.rate_mbps > 0 ? (", link " + std::to_string(o.rate_mbps) + " Mbit/s").c_str() : "");
        if (so.tls)
            std::printf("serve: TLS certificate: %s\n", so.tls->certificate_summary().c_str());
        if (http)
            std::printf("serve: page at %s://%s/ (WebSocket /ws)\n", so.tls ? "https" : "http",
                        remote::host_port(at.host, http->port()).c_str());
        std::fflush(stdout);
        server.serve(stop_requested());
        std::printf("serve: stopped after %d connection(s)\n", server.accepted());
        std::fflush(stdout);
    }
    // A signal stopped it: the server has closed every connection; the signal itself ends the
    // process, as it ends every other command (exit 128 + signal).
    end_by_stop_signal();
    return 0;
}

}  // namespace isowall
