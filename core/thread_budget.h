#pragma once
// One thread budget per rank (STYLE.md, "Threads"): how many threads this rank's work may run at
// once. Ranks can share a node, so the machine's core count is not the rank's to take: whoever
// starts the rank decides its budget and hands it down, and code that starts threads (the octree
// build, extraction workers) takes it as a parameter instead of asking the machine.
#include <algorithm>
#include <ostream>
#include <thread>

namespace isowall {

struct ThreadBudget {
    int threads = 1;  // values below 1 are read as 1 (usable()), so a zero budget still runs

    // Every core of the machine: the budget of a rank that has the node to itself.
    static ThreadBudget hardware() {
        return {std::max(1, static_cast<int>(std::thread::hardware_concurrency()))};
    }
    int usable() const { return std::max(1, threads); }
};

// A rank's share of its node: the cores it may run on (its CPU affinity, which mpirun's binding
// may narrow), but no more than the node's cores divided among the ranks on it, and at least one.
// Five ranks of a wall emulated on 2 cores get 1 each; one rank per 16-core display node, 16.
inline ThreadBudget node_share(int allowed_cores, int node_cores, int ranks_on_node) {
    const int split = std::max(1, node_cores) / std::max(1, ranks_on_node);
    return {std::max(1, std::min(std::max(1, allowed_cores), split))};
}

inline bool operator==(ThreadBudget a, ThreadBudget b) {
    return a.threads == b.threads;
}

inline std::ostream& operator<<(std::ostream& os, ThreadBudget b) {
    return os << "ThreadBudget{" << b.threads << "}";
}

}  // namespace isowall
