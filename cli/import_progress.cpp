#include "cli/import_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace isowall {

ImportProgressBar::ImportProgressBar(std::string label, bool quiet)
    : label_(std::move(label)), quiet_(quiet), tty_(::isatty(2) == 1) {}

void ImportProgressBar::update(const store::ImportProgress& p) {
    if (quiet_ || p.chunks_total == 0) return;
    const double done = double(p.chunks_done) / double(p.chunks_total);
    const double s = sw_.seconds();
    const double mib = double(p.bytes_in) / (1024.0 * 1024.0);
    const double rate = mib / std::max(s, 1e-9);
    const double left = done > 0 ? s * (1 - done) / done : 0;
    const int quarter = static_cast<int>(done * 4);
    if (!tty_ && quarter == last_quarter_) return;
    last_quarter_ = quarter;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(done * kWidth);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(kWidth - filled), '.');
    std::fprintf(stderr, "%s%s: [%s] %3.0f%%  %.0f MiB  %.0f MiB/s  %.1f s left%s",
                 tty_ ? "\r" : "", label_.c_str(), bar.c_str(), 100 * done, mib, rate, left,
                 tty_ ? "" : "\n");
    std::fflush(stderr);
}

void ImportProgressBar::finish() {
    if (!quiet_ && tty_) std::fprintf(stderr, "\n");
}

}  // namespace isowall
