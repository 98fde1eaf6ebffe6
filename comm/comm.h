#pragma once
// The thin messaging layer between the master and the tile ranks (STYLE.md: IceT's communicator,
// OSPRay's MPI_CALL). Only comm_mpi.cpp includes mpi.h; the wall logic talks to this interface.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <memory>
#include <optional>
#include <utility>
#include <span>
#include <string>
#include <vector>

#include "common/wall/wall.h"  // kMasterRank

namespace isowall {

// view: master -> tile, a new frame (interrupts the current one); snapshot: master -> tile, send
// the current image; quit: master -> tile, send the final result and stop; progress and image:
// tile -> master; tile_result: tile -> master, the last message of a tile; hello: tile -> master,
// its host name, first thing.
enum class Tag : int { view = 1, tile_result = 2, snapshot = 3, quit = 4, progress = 5, image = 6, hello = 7 };

class Comm {
public:
    virtual ~Comm() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    bool is_master() const { return rank() == kMasterRank; }
    virtual std::string host() const = 0;
    virtual void send(int dest, Tag tag, std::span<const std::byte> bytes) = 0;
    // Blocks until a message with `tag` from `source` arrives.
    virtual std::vector<std::byte> recv(int source, Tag tag) = 0;
    // The tag of a message from `source` (any rank when source < 0) waiting to be received, if
    // any (does not block).
    virtual std::optional<Tag> probe(int source) = 0;
    // Blocks until any message from `source` (or from any rank when source < 0) arrives.
    virtual std::pair<Tag, std::vector<std::byte>> recv_any(int source, int* from = nullptr) = 0;
    virtual void barrier() = 0;
    // Ends every rank of the job at once (a failing rank must not leave others waiting).
    [[noreturn]] virtual void abort(int code) = 0;
};

// MPI_Init (once) and a duplicate of MPI_COMM_WORLD, so our traffic never matches anyone
// else's. Finalizes MPI when destroyed.
std::unique_ptr<Comm> make_mpi_comm(int& argc, char**& argv);

// Little-endian message building, with a version byte first: never raw padded structs.
class MessageWriter {
public:
    explicit MessageWriter(std::uint8_t version) { put(version); }
    template <class T>
    void put(const T& value) {
        const auto* p = reinterpret_cast<const std::byte*>(&value);
        bytes_.insert(bytes_.end(), p, p + sizeof(T));
    }
    void put_bytes(std::span<const std::byte> b) {
        put(static_cast<std::uint64_t>(b.size()));
        bytes_.insert(bytes_.end(), b.begin(), b.end());
    }
    const std::vector<std::byte>& bytes() const { return bytes_; }

private:
    std::vector<std::byte> bytes_;
};

class MessageReader {
public:
    MessageReader(std::span<const std::byte> bytes, std::uint8_t version) : bytes_(bytes) {
        if (get<std::uint8_t>() != version) throw std::runtime_error("message: wrong version");
    }
    template <class T>
    T get() {
        if (pos_ + sizeof(T) > bytes_.size()) throw std::runtime_error("message: truncated");
        T value;
        std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return value;
    }
    std::span<const std::byte> get_bytes() {
        const auto n = static_cast<std::size_t>(get<std::uint64_t>());
        if (pos_ + n > bytes_.size()) throw std::runtime_error("message: truncated");
        auto s = bytes_.subspan(pos_, n);
        pos_ += n;
        return s;
    }

private:
    std::span<const std::byte> bytes_;
    std::size_t pos_ = 0;
};

}  // namespace isowall
