#include "cli/rechunked_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <thread>
#include <vector>

#include "cli/import_progress.h"
#include "core/error.h"
#include "core/util.h"
#include "store/store_format.h"
#include "store/store_writer.h"
#include "volume/octree.h"

namespace isowall {
namespace fs = std::filesystem;

namespace {

// Every file under a folder store, in a fixed order (the key digests their stats).
std::vector<fs::path> files_under(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
        if (it->is_regular_file(ec)) files.push_back(it->path());
    std::sort(files.begin(), files.end());
    return files;
}

// A lock on `path` held while it lives (flock: the kernel lets it go when a process dies).
class FileLock {
  public:
    explicit FileLock(const fs::path& path) : fd_(::open(path.c_str(), O_RDWR | O_CREAT, 0644)) {
        if (fd_ < 0) throw InputError(path.string(), "lock", "cannot be created");
        if (::flock(fd_, LOCK_EX) != 0) {
            ::close(fd_);
            throw InputError(path.string(), "lock", "cannot be taken");
        }
    }
    ~FileLock() { ::close(fd_); }
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;

  private:
    int fd_;
};

}  // namespace

std::string rechunk_key(const std::string& source, const PlaneSource& planes) {
    const glm::ivec3 d = planes.dims();
    const glm::vec3 s = planes.spacing();
    char shape[160];
    std::snprintf(shape, sizeof shape, "%d %d %d %d %.9g %.9g %.9g", d.x, d.y, d.z,
                  int(planes.type()), double(s.x), double(s.y), double(s.z));
    // A folder by its absolute path (with what follows it: a selection), and its files, each by
    // path, size, times and inode; a URL's objects cannot be stat'ed: its copy is kept until the
    // cache folder is cleared, as its fetched objects are.
    std::string text = source;
    std::error_code ec;
    const std::size_t colon = source.rfind(':');
    for (const std::size_t end : {source.size(), colon})
        if (end != std::string::npos && fs::is_directory(source.substr(0, end), ec)) {
            const fs::path dir = fs::weakly_canonical(source.substr(0, end), ec);
            const auto key = octree_cache::key_for(files_under(dir), planes.type(), d);
            text = dir.string() + source.substr(end) + "\n" +
                   (key ? std::to_string(key->sources) : "unreadable");
            break;
        }
    text += std::string("\n") + shape;
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx",
                  static_cast<unsigned long long>(octree_cache::checksum(
                      {reinterpret_cast<const std::byte*>(text.data()), text.size()})));
    return hex;
}

RechunkedStore rechunk_into_cache(const std::string& source, PlaneSource& planes,
                                  const fs::path& cache_dir, bool quiet) {
    Stopwatch sw;
    const fs::path dir = cache_dir / "stores";
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string(), "cache folder", "cannot be created: " + ec.message());
    const std::string key = rechunk_key(source, planes);
    RechunkedStore out;
    out.store = dir / (key + ".zarr");
    const FileLock lock(dir / (key + ".lock"));
    if (!store::is_store(out.store)) {
        store::ImportOptions opts;
        opts.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
        opts.replace = true;  // a folder left at that name is not a whole store
        ImportProgressBar bar("re-chunk", quiet);
        opts.progress = [&bar](const store::ImportProgress& p) { bar.update(p); };
        store::write_store(planes, out.store, opts);
        bar.finish();
        out.written = true;
    }
    out.seconds = sw.seconds();
    return out;
}

}  // namespace isowall
