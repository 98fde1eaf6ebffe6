#include "volume/inflate_stream.h"

#include <sys/mman.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <climits>

#include "core/error.h"

namespace isowall {

struct InflateStream::State {
    std::span<const std::byte> in;
    std::uint64_t total, left;  // inflated bytes in all, and still to come
    std::string where, field;
    z_stream z{};
    std::size_t pos = 0;       // input consumed
    std::size_t released = 0;  // input pages let go
    bool ended = false;        // the last member ended

    [[noreturn]] void fail(const std::string& what) const { throw InputError(where, field, what); }

    // The input's pages before `pos`, let go of once a few MiB have passed (a mapped file's
    // pages would otherwise stay resident until the end).
    void release() {
        const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
        const auto base = reinterpret_cast<std::uintptr_t>(in.data());
        const std::uintptr_t b = (base + released + page - 1) / page * page;
        const std::uintptr_t e = (base + pos) / page * page;
        if (e > b + (std::uintptr_t{8} << 20)) {
            ::madvise(reinterpret_cast<void*>(b), e - b, MADV_DONTNEED);
            released = e - base;
        }
    }
};

InflateStream::InflateStream(std::span<const std::byte> in, std::uint64_t total, std::string where,
                             std::string field)
    : s_(std::make_unique<State>()) {
    s_->in = in;
    s_->total = s_->left = total;
    s_->where = std::move(where);
    s_->field = std::move(field);
    if (inflateInit2(&s_->z, 15 + 32) != Z_OK) s_->fail("cannot start zlib");
}

InflateStream::~InflateStream() {
    inflateEnd(&s_->z);
}

void InflateStream::read(std::byte* to, std::size_t n) {
    State& s = *s_;
    if (n > s.left) s.fail("asked for more than the stream holds");
    std::size_t done = 0;
    while (done < n) {
        if (s.ended)
            s.fail("the compressed data ends early: the file is shorter than the header says");
        const unsigned in_n = unsigned(std::min<std::size_t>(s.in.size() - s.pos, UINT_MAX));
        const unsigned out_n = unsigned(std::min<std::size_t>(n - done, UINT_MAX));
        s.z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(s.in.data() + s.pos));
        s.z.avail_in = in_n;
        s.z.next_out = reinterpret_cast<Bytef*>(to + done);
        s.z.avail_out = out_n;
        const int rc = inflate(&s.z, Z_NO_FLUSH);
        s.pos += in_n - s.z.avail_in;
        done += out_n - s.z.avail_out;
        if (rc == Z_STREAM_END) {
            if (s.pos < s.in.size() && starts_gzip(s.in.subspan(s.pos)))
                inflateReset(&s.z);  // another gzip member
            else
                s.ended = true;
            continue;
        }
        const bool stalled = s.z.avail_in == in_n && s.z.avail_out == out_n;
        if (rc == Z_OK || (rc == Z_BUF_ERROR && !stalled)) continue;
        if (rc == Z_BUF_ERROR)
            s.fail("the compressed data ends early: the file is shorter than the header says");
        s.fail(std::string("the compressed data is corrupt: ") +
               (s.z.msg ? s.z.msg : "inflate failed"));
    }
    s.left -= n;
    s.release();
    if (s.left > 0) return;
    // The end: the stream must end here, with nothing after it.
    if (!s.ended) {
        std::byte extra;
        s.z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(s.in.data() + s.pos));
        s.z.avail_in = unsigned(std::min<std::size_t>(s.in.size() - s.pos, UINT_MAX));
        s.z.next_out = reinterpret_cast<Bytef*>(&extra);
        s.z.avail_out = 1;
        const int rc = inflate(&s.z, Z_NO_FLUSH);
        s.pos = s.in.size() - s.z.avail_in;
        if (rc != Z_STREAM_END || s.z.avail_out == 0)
            s.fail("the compressed data inflates past the exactly " + std::to_string(s.total) +
                   " bytes the header says");
    }
    if (s.pos != s.in.size())
        s.fail(std::to_string(s.in.size() - s.pos) +
               " bytes follow the compressed data (the file is longer than it)");
}

}  // namespace isowall
