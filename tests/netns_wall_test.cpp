// `isowall wall` across hosts for real: the 2x2 wall run over three emulated hosts
// gives the mosaic of the same wall on one host. The hosts are network namespaces joined by veth
// links to a bridge (scripts/netns_hosts.sh), each with a name of its own; mpirun runs on the
// first, reads a plain hostfile and starts its daemons on the others through Open MPI's rsh
// launcher, with scripts/netns_agent.sh in place of ssh; ranks talk over TCP only. So the
// README's cluster recipe runs here, not only on a cluster.
//
// Needs root (namespaces), `ip netns` and mpirun; skips with the reason when one is missing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/util.h"
#include "files/image_io.h"
#include "tests/image_compare.h"
#include "tests/run_util.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

using test::isowall_cmd;
using test::mpirun;
using test::run;
using test::slurp;

constexpr int kGuardS = 90;    // the test's own limit on each run (both take seconds)
constexpr int kSkipCode = 77;  // netns_hosts.sh: this machine cannot make namespaces

// PNG files carry no depth: a pixel is covered where its colour is not the black background.
const test::CompareOptions kFromFiles{.coverage = test::Coverage::colour};

// The same wall, view and options for both runs; only the mosaic's name differs. The limits end
// a run that cannot start or goes silent (a host unreachable) long before the guard.
std::string wall_args(const std::filesystem::path& dir, const std::string& mosaic) {
    return "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" + (dir / mosaic).string() +
           "' --startup-timeout 40 --timeout 30";
}

// The cluster's mpirun, as a script run on h1: the hostfile and agent come from netns_hosts.sh,
// and both Open MPI's own channel (oob) and the ranks' messages (btl) use only the bridge's
// subnet. No shared memory: ranks on one host talk over TCP too.
// With `hide`, that folder is seen on h1 only (scripts/netns_agent.sh: ISOWALL_NETNS_HIDE).
std::string cluster_script(const std::string& args, const std::filesystem::path& hide = {}) {
    std::string s = "set -eu\n";
    if (!hide.empty()) s += "export ISOWALL_NETNS_HIDE='" + hide.string() + "'\n";
    s += "exec mpirun --hostfile \"$ISOWALL_NETNS_HOSTFILE\"";
    s += " --mca plm_rsh_agent \"$ISOWALL_NETNS_AGENT\"";
    s += " --mca oob_tcp_if_include \"$ISOWALL_NETNS_SUBNET\"";
    s += " --mca btl_tcp_if_include \"$ISOWALL_NETNS_SUBNET\" --mca btl tcp,self";
    s += " --oversubscribe -np 5 " + isowall_cmd() + args + "\n";
    return s;
}

// The master's map: the master's host ("master on h1") and each tile rank's ("rank 2 on h2").
std::map<int, std::string> hosts_of_ranks(const std::string& log) {
    // Parsed by hand, not with <regex>: GCC 12 with sanitizers warns falsely inside it
    // (-Wmaybe-uninitialized), which breaks CI's ASan build.
    std::map<int, std::string> hosts;
    std::istringstream lines(log);
    for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::vector<std::string> w;
        for (std::string word; words >> word;) w.push_back(word);
        for (std::size_t i = 0; i + 2 < w.size(); ++i) {
            if (w[i] == "master" && w[i + 1] == "on" && !hosts.count(0)) hosts[0] = w[i + 2];
            const bool digits = i + 4 < w.size() && !w[i + 1].empty() &&
                                w[i + 1].find_first_not_of("0123456789") == std::string::npos;
            if (w[i] == "rank" && digits && w[i + 2] == "on" && w[i + 4] == "->")
                hosts[std::stoi(w[i + 1])] = w[i + 3];
        }
    }
    return hosts;
}

// The namespaces a run made (its map's second column) that still exist: `ip netns` keeps each
// as a mount under /run/netns.
std::string namespaces_left(const std::filesystem::path& map) {
    std::ifstream in(map);
    std::string line, left;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string address, ns;
        if (line.empty() || line[0] == '#' || !(fields >> address >> ns)) continue;
        if (std::filesystem::exists("/run/netns/" + ns)) left += ns + " ";
    }
    return left;
}

// cluster.png against one.png in `dir`. Not bit-identical in general: with balancing, which rank
// casts which region depends on timing, and so do a few sub-pixel triangles (the README's
// balanced-versus-static rule). On a miss the difference images are written as `name`.
void expect_same_mosaic(const std::filesystem::path& dir, const std::string& name) {
    const Image one = read_image(dir / "one.png");
    const Image cluster = read_image(dir / "cluster.png");
    ASSERT_EQ(cluster.width, one.width);
    ASSERT_EQ(cluster.height, one.height);
    const test::ImageComparison m = test::compare_images(cluster, one, kFromFiles);
    std::cout << name << ": three hosts vs one: " << m << "\n";
    EXPECT_GE(m.mask_iou, 0.999) << m;
    EXPECT_GE(m.equal_share, 0.999) << m;
    if (m.mask_iou < 0.999 || m.equal_share < 0.999)
        test::write_diff_images(dir, name, cluster, one, kFromFiles);
}

TEST(NetnsWall, TheTwoByTwoWallAcrossThreeNamespaceHostsGivesTheMosaicOfOneHost) {
    if (::geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
    if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
    const auto dir = test::scratch_dir("netns_wall");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    std::ofstream(dir / "cluster.sh") << cluster_script(wall_args(dir, "cluster.png"));

    // Across hosts first: where this machine cannot make namespaces, the test skips at once.
    // h1 runs mpirun and holds the master and tile 0, h2 tiles 1-2, h3 tile 3.
    Stopwatch took;
    const std::string hosts = std::string(ISOWALL_SOURCE_DIR) + "/scripts/netns_hosts.sh";
    const int rc = run("bash '" + hosts + "' --slots 2,2,1 --dir '" + (dir / "hosts").string() +
                           "' -- bash '" + (dir / "cluster.sh").string() + "'",
                       dir / "cluster.log", kGuardS);
    const std::string log = slurp(dir / "cluster.log");
    if (rc == kSkipCode && log.find("netns_hosts: skip:") != std::string::npos) GTEST_SKIP() << log;
    const double cluster_s = took.seconds();
    EXPECT_EQ(namespaces_left(dir / "hosts" / "hosts.netns"), "") << "teardown left them";
    ASSERT_EQ(rc, 0) << log;
    ASSERT_EQ(run(mpirun(5) + wall_args(dir, "one.png"), dir / "one.log", kGuardS), 0)
        << slurp(dir / "one.log");
    std::printf("three namespace hosts %.1f s, one host %.1f s\n", cluster_s,
                took.seconds() - cluster_s);

    // The ranks really are on three hosts, as the hostfile's slots place them (the one-host run,
    // for contrast, names one).
    const std::map<int, std::string> at = hosts_of_ranks(log);
    for (const auto& [rank, host] : at) std::printf("rank %d on %s\n", rank, host.c_str());
    const std::map<int, std::string> expected{
        {0, "h1"}, {1, "h1"}, {2, "h2"}, {3, "h2"}, {4, "h3"}};
    EXPECT_EQ(at, expected) << log;
    std::set<std::string> one_host;
    for (const auto& [rank, host] : hosts_of_ranks(slurp(dir / "one.log"))) one_host.insert(host);
    EXPECT_EQ(one_host.size(), 1u) << slurp(dir / "one.log");

    expect_same_mosaic(dir, "netns_mosaic");
}

// Bricks over MPI: the store lies on h1's disk only (the display nodes h2 and h3 see an
// empty folder there). The ranks on h2 and h3 get its metadata, octree and every chunk they touch
// from the master; the mosaic is the one the same store gives on one host.
TEST(NetnsWall, AStoreOnTheFirstHostOnlyGivesTheMosaicOfOneHost) {
    if (::geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
    if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
    const auto dir = test::scratch_dir("netns_store");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    std::filesystem::create_directories(dir / "data");
    {
        const Volume v = make_phantom();
        std::ofstream(dir / "phantom.raw", std::ios::binary)
            .write(reinterpret_cast<const char*>(v.bytes().data()),
                   static_cast<std::streamsize>(v.bytes().size()));
    }
    const std::string store = (dir / "data" / "phantom.zarr").string();
    ASSERT_EQ(run(isowall_cmd() + "import '" + (dir / "phantom.raw").string() +
                      "' --dims 200 184 168 --type uint8 -q --out '" + store + "'",
                  dir / "import.log"),
              0)
        << slurp(dir / "import.log");
    // Each run's octree copies in a cache of its own, so the first run's cannot serve the second.
    auto args = [&](const std::string& mosaic) {
        return wall_args(dir, mosaic) + " --volume '" + store +
               "' --iso 50 --memory-limit 16M --cache-dir '" +
               (dir / ("cache-" + mosaic)).string() + "'";
    };
    std::ofstream(dir / "cluster.sh") << cluster_script(args("cluster.png"), dir / "data");
    const std::string hosts = std::string(ISOWALL_SOURCE_DIR) + "/scripts/netns_hosts.sh";
    const int rc = run("bash '" + hosts + "' --slots 2,2,1 --dir '" + (dir / "hosts").string() +
                           "' -- bash '" + (dir / "cluster.sh").string() + "'",
                       dir / "cluster.log", kGuardS);
    const std::string log = slurp(dir / "cluster.log");
    if (rc == kSkipCode && log.find("netns_hosts: skip:") != std::string::npos) GTEST_SKIP() << log;
    ASSERT_EQ(rc, 0) << log;
    // Ranks 2 and 3 on h2 and rank 4 on h3 asked; rank 1, on h1 with the master, read its disk.
    EXPECT_NE(log.find("sent by the master to 3 rank(s)"), std::string::npos) << log;
    ASSERT_EQ(run(mpirun(5) + args("one.png"), dir / "one.log", kGuardS), 0)
        << slurp(dir / "one.log");
    EXPECT_EQ(slurp(dir / "one.log").find("sent by the master"), std::string::npos);
    expect_same_mosaic(dir, "netns_store");
}

}  // namespace
}  // namespace isowall
