// `isowall view`: the remote-viewing client. Connects, draws each view's groups as they arrive,
// and writes the final image, snapshots and the timeline of what it had on screen.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/remote_commands.h"
#include "cli/cli_checks.h"
#include "cli/iso_option.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/number.h"
#include "core/util.h"
#include "files/image_io.h"
#include "files/output_files.h"
#include "remote/net/endpoint.h"
#include "remote/view_client.h"
#include "render/renderer.h"
#include "wall_spec/script.h"

namespace isowall {
namespace {

using namespace remote;

// The study's cases (the dissertation's section 4.2, and ours as the fifth).
struct CaseSetting {
    GroupEncoding encoding;
    LodSchedule lod;
    bool cache;
    bool adaptive = false;  // the server chooses cells or compact+zstd per group
};
constexpr LodSchedule kOff = LodSchedule::off, kOn = LodSchedule::on;
constexpr CaseSetting kCases[] = {
    {GroupEncoding::vertices, kOff, false},    // 1 base
    {GroupEncoding::indexed, kOff, false},     // 2 primitive compression
    {GroupEncoding::indexed, kOn, false},      // 3 + progressive LOD
    {GroupEncoding::indexed, kOn, true},       // 4 + cached primitives
    {GroupEncoding::compact_zstd, kOn, true},  // 5 ours: compact + zstd
    {GroupEncoding::cells, kOn, true},         // 6 cells
    {GroupEncoding::cells, kOn, true, true}};  // 7 the server chooses (auto)

GroupEncoding parse_encoding(const std::string& s) {
    if (s == "auto") return GroupEncoding::cells;  // and the hello asks the server to choose
    for (GroupEncoding e : kAllGroupEncodings) {
        std::string name = to_string(e);
        for (char& ch : name)
            if (ch == '_' || ch == '+') ch = '-';
        if (name == s) return e;
    }
    throw InputError(
        "--encoding", "value",
        "expected auto, vertices, indexed, compact, compact-zstd or cells, got " + quote(s));
}

struct Viewer {
    const ViewCommand& o;
    ViewClient& client;
    CaseSetting setting;
    glm::ivec2 size;
    Camera camera;
    double iso = 0;
    int frames = 0;
    std::vector<std::string> csv;

    FrameView view() const {
        const Camera c = fit_depth_range(camera, client.ready().bounds);
        return {c, c.frustum(float(size.x) / float(size.y)), size.x, size.y, iso, {}};
    }
    void send() { client.request(view(), setting.lod, setting.cache); }

    void report(const ClientFrameResult& r) {
        ++frames;
        const ClientSample& last = r.timeline.back();
        std::printf(
            "view: frame %d done in %.3f s: %llu bytes, %llu groups (%llu as cells), %llu made "
            "exact after a step, %llu named, %llu triangles drawn\n",
            frames, last.time_s, (unsigned long long)last.bytes, (unsigned long long)last.groups,
            (unsigned long long)last.cells, (unsigned long long)last.exact,
            (unsigned long long)last.named, (unsigned long long)last.triangles);
        for (double th : {0.90, 0.99, 0.999, 1.0}) {
            const ClientSample* hit = nullptr;
            for (const ClientSample& s : r.timeline)
                if (s.correctness.c >= th - 1e-12) {
                    hit = &s;
                    break;
                }
            if (hit)
                std::printf("  C >= %5.1f%%: %8.3f s  %12llu bytes\n", 100 * th, hit->time_s,
                            (unsigned long long)hit->bytes);
        }
        // The coarse passes' picture: the last sample before the full resolution drew.
        const ClientSample* coarse = nullptr;
        for (const ClientSample& s : r.timeline)
            if (s.level > 0) coarse = &s;
        if (coarse)
            std::printf(
                "  coarse passes: C = %.4f by %.3f s, %llu bytes, %llu groups, %llu "
                "triangles\n",
                coarse->correctness.c, coarse->time_s, (unsigned long long)coarse->bytes,
                (unsigned long long)coarse->groups, (unsigned long long)coarse->triangles);
        for (const ClientSample& s : r.timeline) {
            char line[256];
            std::snprintf(line, sizeof(line), "%d,%.6f,%llu,%llu,%llu,%llu,%.6f,%.6f", frames,
                          s.time_s, (unsigned long long)s.bytes, (unsigned long long)s.groups,
                          (unsigned long long)s.named, (unsigned long long)s.triangles,
                          s.correctness.final_pixels, s.correctness.c);
            csv.emplace_back(line);
        }
        std::fflush(stdout);
    }

    void wait_done() {
        if (client.frame_active()) report(client.wait_done(o.timeout_s));
    }

    // One script command; false for quit.
    bool execute(const ScriptCommand& cmd, const std::string& where) {
        if (apply_camera_command(cmd, camera, float(size.x) / float(size.y))) {
        } else if (const auto* c = std::get_if<IsoCmd>(&cmd)) {
            const ReadyMsg& r = client.ready();
            if (!c->surfaces.empty())  // several, or one with a colour or opacity
                throw InputError(where, "iso", "the remote viewer shows one plain surface: iso V");
            iso = checked_isovalue(c->iso, r.value_min, r.value_max, where, "iso");
        } else if (const auto* c = std::get_if<WaitCmd>(&cmd)) {
            if (c->until == WaitCmd::Until::time)
                client.receive_for(c->amount);
            else
                wait_done();
            return true;
        } else if (const auto* c = std::get_if<SnapshotCmd>(&cmd)) {
            const auto path = std::filesystem::path(o.out).parent_path() / (c->name + ".png");
            Image img;
            client.frames().read_back(img);
            write_image(path, img);
            std::printf("snapshot: %s\n", path.c_str());
            return true;
        } else if (std::holds_alternative<QuitCmd>(cmd)) {
            return false;
        } else if (std::holds_alternative<TimeCmd>(cmd) || std::holds_alternative<PlayCmd>(cmd) ||
                   std::holds_alternative<PauseCmd>(cmd)) {
            throw InputError(where, "time",
                             "the remote viewer shows one volume; a series plays "
                             "on the wall (isowall wall --volume PATTERN)");
        }
        if (std::string p = camera_problem(camera); !p.empty())
            throw InputError(where, "camera", p);
        send();
        return true;
    }
};

}  // namespace

CLI::App* add_view_command(CLI::App& app, ViewCommand& o) {
    auto* c = app.add_subcommand(
        "view",
        "Remote-viewing client: asks isowall serve for views and draws their groups as "
        "they arrive");
    c->add_option("--connect", o.connect, "Server as HOST:PORT")->capture_default_str();
    c->add_option("--dataset", o.dataset, "Dataset name the server offers")->capture_default_str();
    c->add_option("--token", o.token, "The server's token, if it asks for one");
    c->add_flag("--tls", o.tls,
                "Connect over TLS (a server started with --tls-cert); its certificate must chain "
                "to an authority the system trusts and name the --connect host");
    c->add_option("--tls-ca", o.tls_ca,
                  "Connect over TLS, trusting the authorities in this PEM file (a self-signed "
                  "server certificate may be its own)");
    c->add_option("--case", o.test_case,
                  "The study's cases: 1 base, 2 indexed, 3 indexed + progressive LOD, 4 indexed "
                  "+ LOD + cache, 5 compact+zstd + LOD + cache, 6 cells + LOD + cache, 7 auto + "
                  "LOD + cache (overrides the three options below)")
        ->check(CLI::Range(1, 7));
    c->add_option("--encoding", o.encoding,
                  "How groups travel: auto (the server sends each group as cells or "
                  "compact-zstd, whichever its link and CPU bring sooner), vertices, indexed, "
                  "compact, compact-zstd, or cells (the units and the voxel values marching "
                  "cubes needs; the client triangulates)")
        ->check(CLI::IsMember({"auto", "vertices", "indexed", "compact", "compact-zstd", "cells"}))
        ->capture_default_str();
    auto* lod = c->add_flag("--lod", o.lod,
                            "Progressive LOD on every frame: two coarser levels of detail first "
                            "(by default the server sends them where it forecasts that they bring "
                            "C = 90% sooner)");
    c->add_flag("--no-lod", o.no_lod, "No progressive LOD: the full resolution only")
        ->excludes(lod);
    c->add_flag("--cache", o.cache, "Cache groups per isovalue (the server names visible ones)");
    c->add_flag("--exact-only", o.exact_only,
                "Every group exact in one message (otherwise a cells group the client does not "
                "cache may come with the voxels that make only its normals to a step, and their "
                "exact values once the frame's last group is out)");
    add_iso_option(*c, o.iso);
    c->add_option("--size", o.size, "Image size WIDTHxHEIGHT")->capture_default_str();
    c->add_option("--orbit", o.orbit, "Rotate the front view: YAW PITCH in degrees")
        ->expected(2)
        ->transform(number_in(limits::kAngleDeg));
    c->add_option("--zoom", o.zoom, "Zoom factor (>1 moves closer)")
        ->transform(number_in(limits::kZoom))
        ->capture_default_str();
    c->add_option("--script", o.script,
                  "Commands as for the wall (orbit, zoom, pan, look, iso, wait done, wait time "
                  "S, snapshot NAME, quit); each view change is sent at once and interrupts the "
                  "frame in progress");
    c->add_option("--out,-o", o.out, "The last frame's final image")->capture_default_str();
    c->add_option("--timeline", o.timeline,
                  "CSV: frame, time_s, bytes, groups, named, triangles, final_pixels, c");
    c->add_option("--gl", o.gl, "OpenGL back end")
        ->check(CLI::IsMember({"osmesa", "egl"}))
        ->capture_default_str();
    c->add_option("--present", o.present,
                  "Share the views as session NAME: every view asked here is extracted once and "
                  "streamed to the session's followers too");
    c->add_option("--follow", o.follow,
                  "Follow session NAME: draw every view its presenter asks for, writing --out "
                  "after each frame (the encoding must be the presenter's)");
    c->add_option("--frames", o.frames,
                  "With --follow: end after this many frames (0: when the "
                  "server ends the connection)")
        ->check(CLI::Range(0, 1 << 30));
    c->add_option("--timeout", o.timeout_s,
                  "Give up when nothing arrives for this long (s), from the connection on")
        ->transform(number_in(limits::kSeconds))
        ->capture_default_str();
    return c;
}

namespace {

// --follow: every frame the presenter's views give, until --frames or the connection ends.
int follow_session(const ViewCommand& o, ViewClient& client, Viewer& v) {
    for (;;) {
        const ClientFrameResult* r = nullptr;
        try {
            r = client.next_frame(1.0);  // a presenter may leave a view up for as long as it likes
        } catch (const PeerClosed&) {
            std::printf("view: the server ended the connection after %d frame(s)\n", v.frames);
            return 0;
        }
        if (!r) continue;
        if (client.session())
            std::printf("view: session %s, presenter %s, %u member(s)\n",
                        client.session()->session.c_str(),
                        client.session()->presenter.empty() ? "(none)"
                                                            : client.session()->presenter.c_str(),
                        client.session()->members);
        v.report(*r);
        OutputFiles batch;
        write_image(batch, o.out, r->final_image);
        batch.commit();
        std::printf("wrote %s\n", o.out.c_str());
        std::fflush(stdout);
        if (o.frames > 0 && v.frames >= o.frames) {
            client.close();
            return 0;
        }
    }
}

void check_session_options(const ViewCommand& o) {
    if (!o.present.empty() && !o.follow.empty())
        throw InputError("--follow", "value", "a client presents a session or follows one");
    if (!o.follow.empty() && (!o.script.empty() || !o.orbit.empty() || o.iso || o.zoom != 1.0))
        throw InputError("--follow", "value",
                         "a follower asks for no views (--script, --orbit, --iso, --zoom): the "
                         "presenter's come by themselves");
    if (o.frames > 0 && o.follow.empty())
        throw InputError("--frames", "value", "counts a follower's frames: give --follow NAME");
}

}  // namespace

int run_view(const ViewCommand& o) {
    check_session_options(o);
    const auto size = parse_size(o.size);
    if (!size)
        throw InputError(
            "--size", "value",
            "expected WIDTHxHEIGHT, each an integer in [1, 32768], got " + quote(o.size));
    std::vector<OutputPath> outputs{{"--out", o.out}};
    if (!o.timeline.empty()) outputs.push_back({"--timeline", o.timeline});
    check_outputs(outputs);
    if (std::string p = image_format_problem(o.out); !p.empty())
        throw InputError(o.out, "--out", p);
    std::vector<ScriptLine> script;
    if (!o.script.empty()) script = load_script(o.script);
    const Endpoint ep = parse_endpoint(o.connect, "--connect", "HOST:PORT");
    const LodSchedule lod = o.lod      ? LodSchedule::on
                            : o.no_lod ? LodSchedule::off
                                       : LodSchedule::chosen;
    CaseSetting setting{parse_encoding(o.encoding), lod, o.cache, o.encoding == "auto"};
    if (o.test_case > 0) setting = kCases[o.test_case - 1];

    auto renderer = make_renderer(o.gl);
    ClientHello hello;
    hello.host = ep.host;
    hello.port = ep.port;
    hello.dataset = o.dataset;
    hello.token = o.token;
    if (o.tls || !o.tls_ca.empty())
        hello.tls = std::make_shared<const TlsContext>(TlsContext::client(o.tls_ca));
    hello.encoding = setting.encoding;
    hello.adaptive = setting.adaptive;
    hello.connect_timeout_s = o.timeout_s;  // connecting and the hello's answer too (once 10 s)
    hello.role = !o.present.empty()  ? SessionRole::presenter
                 : !o.follow.empty() ? SessionRole::follower
                                     : SessionRole::none;
    hello.session = !o.present.empty() ? o.present : o.follow;
    hello.takes_exact = !o.exact_only;
    ViewClient client(*renderer, hello);
    std::printf(
        "view: connected to %s, dataset %s, values [%g, %g], %s, progressive LOD %s%s\n",
        o.connect.c_str(), o.dataset.c_str(), client.ready().value_min, client.ready().value_max,
        hello.adaptive ? "auto (cells or compact+zstd per group)" : to_string(setting.encoding),
        to_string(setting.lod).c_str(), setting.cache ? ", cached groups" : "");
    Viewer v{o, client, setting, *size, {}, 0, 0, {}};
    if (!o.follow.empty()) return follow_session(o, client, v);
    const float aspect = float(size->x) / float(size->y);
    v.camera = front_full_view(client.ready().bounds, client.ready().axes, aspect);
    if (o.orbit.size() == 2) v.camera = orbit(v.camera, o.orbit[0], o.orbit[1]);
    v.camera = zoom(v.camera, float(o.zoom));
    if (std::string p = camera_problem(v.camera); !p.empty())
        throw InputError("--zoom", "value", p);
    v.iso = checked_iso(o.iso, {"dataset " + quote(o.dataset), o.dataset == "phantom",
                                client.ready().value_min, client.ready().value_max});
    v.send();
    for (const ScriptLine& l : script)
        if (!v.execute(l.command, o.script + ":" + std::to_string(l.line))) break;
    v.wait_done();
    client.close();

    OutputFiles batch;
    write_image(batch, o.out, client.frames().result().final_image);
    if (!o.timeline.empty()) {
        std::string text = "frame,time_s,bytes,groups,named,triangles,final_pixels,c\n";
        for (const std::string& line : v.csv) text += line + "\n";
        std::ofstream f(batch.stage(o.timeline), std::ios::binary);
        f << text;
        if (!f.flush()) throw std::runtime_error(o.timeline + ": cannot write the timeline");
    }
    batch.commit();
    std::printf("wrote %s%s%s\n", o.out.c_str(), o.timeline.empty() ? "" : " and ",
                o.timeline.c_str());
    return 0;
}

}  // namespace isowall
