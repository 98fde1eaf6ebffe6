#pragma once
// Whole objects over HTTP(S) through libcurl, for stores served by a web server or an object store
// (one GET per object, no ranges): what `--volume https://host/path.zarr` reads.
//   - 200: the body; 404: absent (a Zarr chunk left out is the fill value); any other status, or
//     a body past `max_bytes`, is an InputError naming the URL and the status.
//   - A refused or dropped connection, a body cut short of its Content-Length, a server that
//     sends nothing for `stall_s` seconds, and 5xx answers are tried again, `retries` more times,
//     after 0.25 s, 0.5 s, 1 s...; the last failure is the error, naming the URL and what happened.
//   - With `cache_dir`, each 200 body is kept there under a hash of its URL and read from there
//     the next time (a store's objects do not change under one URL; remove the folder when one
//     does).
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace isowall::formats {

// "http://..." or "https://...".
bool is_url(std::string_view text);

struct HttpOptions {
    double stall_s = 30;  // no byte for this long: the try failed
    int retries = 3;
    int connections = 8;              // objects fetched at once by get_many
    std::filesystem::path cache_dir;  // empty: no cache
};

class HttpFetcher {
  public:
    explicit HttpFetcher(HttpOptions options);
    ~HttpFetcher();
    HttpFetcher(const HttpFetcher&) = delete;
    HttpFetcher& operator=(const HttpFetcher&) = delete;
    // The body of `url`, nullopt on 404; `field` names the object in errors ("chunk", ".zarray").
    std::optional<std::string> get(const std::string& url, const std::string& field,
                                   std::size_t max_bytes) const;
    // The bodies of `urls` (nullopt for a 404), up to `connections` fetched at once, each as get()
    // fetches it; the first failure in the order of `urls` is thrown, once the fetches under way
    // have ended (none is started after a failure).
    std::vector<std::optional<std::string>> get_many(const std::vector<std::string>& urls,
                                                     const std::string& field,
                                                     std::size_t max_bytes) const;
    // The file that keeps `url`'s body in the cache, where it has been fetched; else empty.
    std::filesystem::path cached_file(const std::string& url) const;
    // How many tries the fetches so far took beyond the first (for messages and tests).
    int retried() const { return retried_; }

  private:
    HttpOptions options_;
    mutable std::atomic<int> retried_{0};
    void* borrow() const;  // a libcurl handle (CURL*), kept ones first
    void give_back(void* handle) const;
    mutable std::mutex handles_mu_;
    mutable std::vector<void*> handles_;  // idle handles, each keeping its connections
};

}  // namespace isowall::formats
