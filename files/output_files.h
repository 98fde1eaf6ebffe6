#pragma once
// Outputs appear whole or not at all. Every file the program writes is written under a temporary
// name beside its target (the same folder, so the final rename is atomic) and renamed into place
// by commit(). The outputs of one command are staged in one OutputFiles and committed together at
// its end; an OutputFiles destroyed uncommitted (an error) removes every temporary it staged. A
// temporary is registered while it lives, so SIGINT, SIGTERM and SIGHUP remove it too
// (install_output_cleanup()).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace isowall {

// Why `target` cannot be written, or empty: it is empty, names a folder or something other than
// a regular file (a device, a pipe), or its folder does not exist or cannot be written. Creates
// nothing (the folder is probed with an unnamed O_TMPFILE where the file system has one).
std::string output_problem(const std::filesystem::path& target);
// InputError(target, option, output_problem(target)) when there is a problem.
void check_output(const std::filesystem::path& target, const std::string& option);

class OutputFiles {
  public:
    OutputFiles() = default;
    OutputFiles(const OutputFiles&) = delete;
    OutputFiles& operator=(const OutputFiles&) = delete;
    // Uncommitted: removes every temporary staged (an error happened before the end).
    ~OutputFiles();

    // A fresh temporary path beside `target` for a writer to fill: hidden, unique per process and
    // call, with `target`'s extension (OpenImageIO picks the format by it). Registered for
    // removal on a signal before the file exists.
    std::filesystem::path stage(const std::filesystem::path& target);
    // Renames every staged file onto its target, in the order staged. When one rename fails, the
    // targets this call already renamed are removed (no partial output) and it throws a
    // std::runtime_error naming the target.
    void commit();
    std::size_t size() const { return staged_.size(); }

  private:
    struct Staged {
        std::filesystem::path temporary, target;
        int slot = -1;  // in the signal-time registry
    };
    std::vector<Staged> staged_;
};

// Writes the `parts`, one after the other, to `file` (created or truncated), checking every write,
// fsync and the close: a full disk or an I/O error is a std::runtime_error naming `name` and the
// cause ("No space left on device"), never a cut-off file that looks written. Writers whose library
// may drop a write error (an image encoder over stdio) encode into memory and write through this.
void write_bytes_checked(const std::filesystem::path& file,
                         std::initializer_list<std::span<const std::byte>> parts,
                         const std::string& name);

// One output alone: stage it, let `write` fill the temporary, commit.
void write_output(const std::filesystem::path& target,
                  const std::function<void(const std::filesystem::path& temporary)>& write);

// Handlers for SIGINT, SIGTERM and SIGHUP that unlink every live temporary (async-signal-safe: a
// fixed table, unlink()) and then end the process by the signal's default action. A signal whose
// disposition is not the default (ignored under nohup, or someone else's handler) is left alone.
void install_output_cleanup();

// The temporaries registered now (for tests).
std::size_t live_temporaries();

// At most this many temporaries are live at once (the registry is a fixed table, so a signal
// handler can walk it); stage() throws beyond it.
inline constexpr std::size_t kMaxLiveTemporaries = 256;

}  // namespace isowall
