#include "readers/http_fetch.h"

#include <curl/curl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <thread>

#include <unistd.h>

#include "core/error.h"

namespace isowall::formats {

namespace {

// One attempt's outcome: a status and a body, or a failure worth another try, or a final one.
struct Attempt {
    long status = 0;
    std::string body;
    std::string failure;  // non-empty: this try failed, with this reason
    bool retry = false;   // whether another try may do better
};

struct Sink {
    std::string* body;
    std::size_t max;
    bool over = false;
};

std::size_t write_body(char* data, std::size_t size, std::size_t count, void* user) {
    auto* s = static_cast<Sink*>(user);
    const std::size_t n = size * count;
    if (s->body->size() + n > s->max) {
        s->over = true;
        return 0;  // aborts the transfer (CURLE_WRITE_ERROR)
    }
    s->body->append(data, n);
    return n;
}

void global_init() {
    static const bool done = [] {
        curl_global_init(CURL_GLOBAL_DEFAULT);
        return true;
    }();
    (void)done;
}

Attempt fetch_once(CURL* handle, const std::string& url, std::size_t max_bytes, double stall_s) {
    Attempt a;
    if (!handle) return {0, {}, "libcurl could not start", false};
    curl_easy_reset(handle);  // its options go; its connections stay
    Sink sink{&a.body, max_bytes};
    const long stall = std::max(1L, std::lround(stall_s));
    curl_easy_setopt(handle, CURLOPT_URL, url.c_str());
    curl_easy_setopt(handle, CURLOPT_PROTOCOLS_STR, "http,https");
    curl_easy_setopt(handle, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
    curl_easy_setopt(handle, CURLOPT_FOLLOWLOCATION, 1L);
    curl_easy_setopt(handle, CURLOPT_MAXREDIRS, 5L);
    curl_easy_setopt(handle, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(handle, CURLOPT_CONNECTTIMEOUT, stall);
    // Less than a byte a second for `stall` seconds: the server stalled.
    curl_easy_setopt(handle, CURLOPT_LOW_SPEED_LIMIT, 1L);
    curl_easy_setopt(handle, CURLOPT_LOW_SPEED_TIME, stall);
    curl_easy_setopt(handle, CURLOPT_WRITEFUNCTION, write_body);
    curl_easy_setopt(handle, CURLOPT_WRITEDATA, &sink);
    curl_easy_setopt(handle, CURLOPT_USERAGENT, "isowall");
    const CURLcode r = curl_easy_perform(handle);
    curl_easy_getinfo(handle, CURLINFO_RESPONSE_CODE, &a.status);
    if (sink.over) {
        a.failure = "the object is larger than " + std::to_string(max_bytes) + " bytes";
        return a;
    }
    switch (r) {
        case CURLE_OK:
            break;
        case CURLE_OPERATION_TIMEDOUT:
            a.failure = "the server sent nothing for " + std::to_string(stall) + " s";
            a.retry = true;
            return a;
        case CURLE_PARTIAL_FILE:
            a.failure = "the body was cut short (" + std::to_string(a.body.size()) +
                        " bytes, fewer than its Content-Length)";
            a.retry = true;
            return a;
        case CURLE_COULDNT_CONNECT:
        case CURLE_RECV_ERROR:
        case CURLE_SEND_ERROR:
        case CURLE_GOT_NOTHING:
            a.failure = curl_easy_strerror(r);
            a.retry = true;
            return a;
        default:
            a.failure = curl_easy_strerror(r);
            return a;
    }
    if (a.status >= 500) {
        a.failure = "HTTP " + std::to_string(a.status);
        a.retry = true;
    } else if (a.status != 200 && a.status != 404) {
        a.failure = "HTTP " + std::to_string(a.status);
    }
    return a;
}

// FNV-1a of the URL, as 16 hex digits: the cache file's name.
std::string url_hash(const std::string& url) {
    std::uint64_t h = 1469598103934665603ull;
    for (const unsigned char c : url) h = (h ^ c) * 1099511628211ull;
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

}  // namespace

bool is_url(std::string_view text) {
    return text.starts_with("http://") || text.starts_with("https://");
}

HttpFetcher::HttpFetcher(HttpOptions options) : options_(std::move(options)) {}

HttpFetcher::~HttpFetcher() {
    for (void* h : handles_) curl_easy_cleanup(static_cast<CURL*>(h));
}

// A handle from the ones kept (their connections kept with them, so the next object from the
// same server needs no TCP or TLS handshake), or a new one.
void* HttpFetcher::borrow() const {
    global_init();
    {
        const std::lock_guard lock(handles_mu_);
        if (!handles_.empty()) {
            void* h = handles_.back();
            handles_.pop_back();
            return h;
        }
    }
    return curl_easy_init();
}

void HttpFetcher::give_back(void* handle) const {
    if (!handle) return;
    const std::lock_guard lock(handles_mu_);
    handles_.push_back(handle);
}

std::filesystem::path HttpFetcher::cached_file(const std::string& url) const {
    if (options_.cache_dir.empty()) return {};
    std::filesystem::path file = options_.cache_dir / url_hash(url);
    std::error_code ec;
    return std::filesystem::is_regular_file(file, ec) ? file : std::filesystem::path();
}

std::optional<std::string> HttpFetcher::get(const std::string& url, const std::string& field,
                                            std::size_t max_bytes) const {
    std::filesystem::path cached;
    if (!options_.cache_dir.empty()) {
        cached = options_.cache_dir / url_hash(url);
        std::ifstream in(cached, std::ios::binary);
        if (in) {
            std::string body((std::istreambuf_iterator<char>(in)), {});
            if (!in.bad() && body.size() <= max_bytes) return body;
        }
    }
    Attempt a;
    for (int attempt = 0;; ++attempt) {
        void* handle = borrow();
        a = fetch_once(static_cast<CURL*>(handle), url, max_bytes, options_.stall_s);
        give_back(handle);
        if (a.failure.empty() || !a.retry || attempt >= options_.retries) break;
        ++retried_;
        std::this_thread::sleep_for(std::chrono::milliseconds(250 << attempt));
    }
    if (!a.failure.empty())
        throw InputError(
            url, field,
            a.failure +
                (a.retry ? " (after " + std::to_string(options_.retries + 1) + " tries)" : ""));
    if (a.status == 404) return std::nullopt;
    if (!cached.empty()) {
        // Written whole under a temporary name, then renamed: a cache file is never a part.
        std::error_code ec;
        std::filesystem::create_directories(cached.parent_path(), ec);
        // A part of its own: other processes (a wall's ranks) may fetch the same object at once.
        static std::atomic<unsigned> parts{0};
        const auto part = cached.string() + "." + std::to_string(::getpid()) + "." +
                          std::to_string(parts++) + ".part";
        std::ofstream out(part, std::ios::binary | std::ios::trunc);
        out.write(a.body.data(), static_cast<std::streamsize>(a.body.size()));
        out.close();
        if (out) std::filesystem::rename(part, cached, ec);
        if (!out || ec) std::filesystem::remove(part, ec);  // a cache that cannot be written
    }
    return std::move(a.body);
}

std::vector<std::optional<std::string>> HttpFetcher::get_many(const std::vector<std::string>& urls,
                                                              const std::string& field,
                                                              std::size_t max_bytes) const {
    std::vector<std::optional<std::string>> out(urls.size());
    std::vector<std::exception_ptr> errors(urls.size());
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        for (std::size_t i; (i = next++) < urls.size();) {
            try {
                out[i] = get(urls[i], field, max_bytes);
            } catch (...) {
                errors[i] = std::current_exception();
                next = urls.size();  // no new object once one failed
            }
        }
    };
    const std::size_t n = std::min<std::size_t>(
        static_cast<std::size_t>(std::max(1, options_.connections)), urls.size());
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < n; ++t) threads.emplace_back(work);
    work();
    for (std::thread& t : threads) t.join();
    for (const std::exception_ptr& e : errors)  // the first failure in the order asked
        if (e) std::rethrow_exception(e);
    return out;
}

}  // namespace isowall::formats
