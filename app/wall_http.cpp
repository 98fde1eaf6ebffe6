#include "app/wall_http.h"

#include <cstdio>

#include "core/error.h"
#include "master/control_input.h"
#include "master/control_view.h"
#include "remote/http/web_routes.h"
#include "remote/view_server.h"

namespace isowall {
namespace {

// Mosaics at most this often: a preview comes from each tile a few times a second.
constexpr double kMosaicIntervalS = 0.1;
// The state again at least this often (the frame's seconds go on while it runs).
constexpr double kStateIntervalS = 0.25;
// Texts a page may leave unsent before it is closed as too slow (states and mosaics never pile
// up: each replaces the last).
constexpr std::size_t kMaxQueuedTexts = 256;

// Who may reach the page, in the terms of `serve`'s (remote/view_server.h).
remote::ServerOptions access_options(const WallHttpOptions& o) {
    remote::ServerOptions so;
    so.address = o.address;
    so.token = o.token;
    so.tls = o.tls;
    so.allowed_hosts = o.allowed_hosts;
    return so;
}

web::WebOptions web_options(const WallHttpOptions& o) {
    web::WebOptions w;
    w.address = o.address;
    w.port = o.port;
    w.max_message_bytes = kMaxPageMessage;
    if (o.tls) w.tls = o.tls->native();
    w.host_names = remote::served_host_names(access_options(o));
    return w;
}

void check_exposure(const WallHttpOptions& o) {
    const std::string p = remote::exposure_problem(access_options(o), "serving the wall's page");
    if (!p.empty()) throw InputError("--http-listen", "address", p);
}

}  // namespace

WallHttp::WallHttp(const WallSpec& spec, WallHttpOptions options)
    : o_(std::move(options)), layout_(control_layout(spec)), pacer_(kMosaicIntervalS), spec_(spec) {
    check_exposure(o_);
    web::WebCallbacks cb;
    cb.http = [](const web::HttpRequest& r) {
        return remote::route(r, remote::RouteContext{{}, "", remote::web_assets(), "wall.html"});
    };
    cb.opened = [this](web::ConnectionId id, const std::string& peer) { opened(id, peer); };
    cb.message = [this](web::ConnectionId id, std::string bytes, bool binary) {
        message(id, std::move(bytes), binary);
    };
    cb.closed = [this](web::ConnectionId id) { closed(id); };
    try {
        web_ = std::make_unique<web::WebServer>(web_options(o_), std::move(cb));
    } catch (const std::exception& e) {
        throw InputError("--http", "port",
                         "cannot serve the page on " + o_.address + ":" + std::to_string(o_.port) +
                             ": " + e.what());
    }
    web_->start();
    encoder_ = std::thread([this] { encode_loop(); });
}

void WallHttp::encode_loop() {
    for (;;) {
        Pictures p;
        {
            std::unique_lock lock(encoder_mutex_);
            encoder_wake_.wait(lock, [&] { return encoder_stop_ || to_encode_; });
            if (encoder_stop_) return;
            p = std::move(*to_encode_);
            to_encode_.reset();
            encoding_ = true;
        }
        const Stopwatch making;
        auto bytes = std::make_shared<const std::string>(
            encode_mosaic(compose_mosaic(layout_, tile_previews(spec_, p.by_rank)), p.frame));
        std::lock_guard lock(encoder_mutex_);
        made_s_ += making.seconds();
        made_bytes_ += bytes->size();
        ++mosaics_;
        encoded_ = std::move(bytes);
        encoding_ = false;
    }
}

WallHttp::~WallHttp() {
    {
        std::lock_guard lock(encoder_mutex_);
        encoder_stop_ = true;
    }
    encoder_wake_.notify_all();
    encoder_.join();
    if (mosaics_ > 0)
        std::printf(
            "http: %llu mosaics of %dx%d made, %.1f KiB each on average, %.2f ms each to "
            "compose and compress; %llu page(s) connected in all\n",
            static_cast<unsigned long long>(mosaics_), layout_.mosaic.width, layout_.mosaic.height,
            double(made_bytes_) / double(mosaics_) / 1024, 1000 * made_s_ / double(mosaics_),
            static_cast<unsigned long long>(next_page_ - 1));
    web_->stop();  // every `closed` runs: each page is in gone_
    std::lock_guard lock(mutex_);
    for (auto& [id, page] : pages_) gone_.push_back(page);
    pages_.clear();
    for (auto& page : gone_) {
        page->closed = true;
        page->wake.notify_all();
        if (page->sender.joinable()) page->sender.join();
    }
}

void WallHttp::opened(web::ConnectionId id, const std::string& peer) {
    std::unique_lock lock(mutex_);
    if (pages_.size() >= o_.max_pages) {
        lock.unlock();
        web_->close(id, "the wall serves " + std::to_string(o_.max_pages) + " pages at most");
        return;
    }
    auto page = std::make_shared<Page>();
    page->id = id;
    page->name = "page " + std::to_string(next_page_++);
    pages_[id] = page;
    page->sender = std::thread([this, p = page.get()] { send_loop(*p); });
    std::printf("http: %s connected from %s\n", page->name.c_str(), clip(peer, 80).c_str());
    std::fflush(stdout);
}

void WallHttp::message(web::ConnectionId id, std::string bytes, bool) {
    std::lock_guard lock(mutex_);
    if (pages_.count(id)) inbox_.push_back({id, std::move(bytes)});
}

void WallHttp::closed(web::ConnectionId id) {
    std::lock_guard lock(mutex_);
    auto it = pages_.find(id);
    if (it == pages_.end()) return;
    it->second->closed = true;
    it->second->wake.notify_all();
    gone_.push_back(it->second);
    pages_.erase(it);
}

void WallHttp::send_loop(Page& page) {
    for (;;) {
        std::deque<std::string> texts;
        std::optional<std::string> state, close_reason;
        std::shared_ptr<const std::string> mosaic;
        {
            std::unique_lock lock(page.mutex);
            page.wake.wait(lock, [&] {
                return page.closed || !page.texts.empty() || page.state || page.mosaic ||
                       page.close_reason;
            });
            if (page.closed) return;
            texts.swap(page.texts);
            state.swap(page.state);
            mosaic.swap(page.mosaic);
            close_reason.swap(page.close_reason);
        }
        if (state && !close_reason) texts.push_back(std::move(*state));
        for (const std::string& t : texts)
            if (!web_->send(page.id, t.data(), t.size(), &page.closed)) return;
        if (mosaic && !close_reason &&
            !web_->send(page.id, mosaic->data(), mosaic->size(), &page.closed))
            return;
        if (close_reason) {
            web_->close(page.id, *close_reason);
            return;
        }
    }
}

void WallHttp::post(Page& page, std::string text) {
    std::lock_guard lock(page.mutex);
    if (page.texts.size() >= kMaxQueuedTexts) {
        web_->close(page.id, "the page is not reading what the wall sends");
        return;
    }
    page.texts.push_back(std::move(text));
    page.wake.notify_one();
}

void WallHttp::broadcast(const std::string& text) {
    for (auto& page : roster_) post(*page, text);
}

void WallHttp::drop(const std::shared_ptr<Page>& page, const std::string& reason) {
    post(*page, error_json(reason));
    std::lock_guard lock(page->mutex);
    page->close_reason = reason;
    page->wake.notify_one();
}

void WallHttp::begin() {
    // The certificate first: whoever waits for the page's address (a script, a test reading the
    // output as it comes) then has the certificate too.
    if (o_.tls) std::printf("http: TLS certificate: %s\n", o_.tls->certificate_summary().c_str());
    std::printf("http: page at %s://%s:%d/ (WebSocket /ws)%s\n", o_.tls ? "https" : "http",
                o_.address.find(':') != std::string::npos ? ("[" + o_.address + "]").c_str()
                                                          : o_.address.c_str(),
                port(), o_.token.empty() ? "" : " (token required)");
    std::fflush(stdout);
}

void WallHttp::handle(const std::shared_ptr<Page>& page, const std::string& bytes,
                      std::vector<SteeringLine>& lines) {
    PageMessage m;
    try {
        m = parse_page_message(bytes, page->name);
    } catch (const InputError& e) {
        post(*page, error_json(e.what()));
        return;
    }
    if (!page->hello) {
        if (m.kind != PageMessage::Kind::hello)
            return drop(page, page->name + ": the first message must be {\"hello\": TOKEN}");
        if (!remote::same_token(m.text, o_.token))
            return drop(page, o_.token.empty() ? "this wall asks for no token"
                                               : "wrong token (the wall's --token)");
        page->hello = true;
        roster_.push_back(page);
        roster_changed_ = true;
        post(*page, welcome_json(page->name, layout_, o_.wall_name));
        if (last_mosaic_) {
            std::lock_guard lock(page->mutex);
            page->mosaic = last_mosaic_;
        }
        return;
    }
    switch (m.kind) {
        case PageMessage::Kind::hello:
            post(*page, error_json(page->name + " has said hello already"));
            return;
        case PageMessage::Kind::take:
            if (seat_.holder() != page->id) {
                std::printf("http: %s steers\n", page->name.c_str());
                std::fflush(stdout);
            }
            seat_.take(page->id);
            roster_changed_ = true;
            return;
        case PageMessage::Kind::run:
        case PageMessage::Kind::snapshot:
            break;
    }
    const std::optional<std::uint64_t> before = seat_.holder();
    if (!seat_.claim(page->id)) {
        std::string steerer;
        for (auto& p : roster_)
            if (p->id == seat_.holder()) steerer = p->name;
        post(*page, error_json(steerer + " steers the wall: take over to steer"));
        return;
    }
    if (before != seat_.holder()) {
        roster_changed_ = true;
        std::printf("http: %s steers\n", page->name.c_str());
        std::fflush(stdout);
    }
    if (m.kind == PageMessage::Kind::snapshot) {  // page-001 ..., the first name not taken
        next_snapshot_ = first_free_snapshot(o_.out, next_snapshot_, "page");
        m.text = "snapshot " + snapshot_name(next_snapshot_++, "page");
    }
    lines.push_back({m.text, page->name});
}

std::vector<SteeringLine> WallHttp::take(const WallMaster&) {
    std::vector<Inbound> inbox;
    std::vector<std::shared_ptr<Page>> gone;
    std::vector<std::shared_ptr<Page>> by_inbox;
    {
        std::lock_guard lock(mutex_);
        inbox.swap(inbox_);
        gone.swap(gone_);
        for (const Inbound& in : inbox) {
            auto it = pages_.find(in.id);
            by_inbox.push_back(it == pages_.end() ? nullptr : it->second);
        }
    }
    std::vector<SteeringLine> lines;
    for (std::size_t i = 0; i < inbox.size(); ++i)
        if (by_inbox[i] && !by_inbox[i]->closed) handle(by_inbox[i], inbox[i].bytes, lines);
    for (auto& page : gone) {
        if (page->sender.joinable()) page->sender.join();
        seat_.leave(page->id);
        if (std::erase(roster_, page) > 0) {
            roster_changed_ = true;
            std::printf("http: %s left\n", page->name.c_str());
            std::fflush(stdout);
        }
    }
    return lines;
}

void WallHttp::ran(const SteeringLine& line, const std::string& error) {
    broadcast(ran_json(line.who, line.text, error));
}

std::string WallHttp::state_of(const WallMaster& master, const FrameNote& frame) const {
    PageState s;
    s.iso = master.iso();
    s.value_min = master.value_min();
    s.value_max = master.value_max();
    s.frame = frame.frame;
    s.done = frame.done;
    s.frame_s = frame.seconds;
    s.figures = master.frame_figures();
    s.dark = master.dark_screens();
    s.clip = clip_text(master.clip());
    s.dims = master.dims();
    for (const SurfaceStyle& one : master.surfaces()) s.surfaces.push_back(surface_style_text(one));
    s.steps = master.options().steps;
    s.step = master.step();
    s.playing = master.playing();
    if (master.options().legend) {
        s.legend = *master.options().legend;
        s.legend_label = master.options().legend_label;
    }
    for (const auto& page : roster_) {
        s.pages.push_back(page->name);
        if (seat_.holder() == page->id) s.steering = page->name;
    }
    return state_json(s);
}

void WallHttp::show(const WallMaster& master, const FrameNote& frame, bool changed) {
    if (roster_.empty()) return;
    const double now = clock_.seconds();
    const bool joined = roster_changed_;
    if (changed || joined || since_state_.seconds() > kStateIntervalS) {
        const std::string state = state_of(master, frame);
        for (auto& page : roster_) {
            std::lock_guard lock(page->mutex);
            page->state = state;
            page->wake.notify_one();
        }
        since_state_.restart();
        roster_changed_ = false;
    }
    // A new picture when a tile sent one (at most every kMosaicIntervalS), or for a page that
    // came before any was made: the encoder makes it; the latest it made goes to every page.
    const bool pictures = master.previews_taken() != previews_seen_;
    std::shared_ptr<const std::string> fresh;
    {
        std::lock_guard lock(encoder_mutex_);
        if ((pictures && pacer_.changed(now)) || pacer_.due(now) ||
            (joined && !last_mosaic_ && !encoding_ && !encoded_)) {
            previews_seen_ = master.previews_taken();
            to_encode_ = Pictures{master.previews(), frame.frame};
            encoder_wake_.notify_one();
        }
        fresh.swap(encoded_);
    }
    if (!fresh) return;
    last_mosaic_ = fresh;
    for (auto& page : roster_) {
        std::lock_guard lock(page->mutex);
        page->mosaic = fresh;
        page->wake.notify_one();
    }
}

}  // namespace isowall
