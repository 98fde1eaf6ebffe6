// Every number a script line carries, against every class of hostile value: one line naming the
// file, line and command, never a NaN or infinite camera.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "tests/test_util.h"
#include "wall_spec/script.h"

namespace isowall {
namespace {

// Each numeric slot of each command, as a line with {} where the value goes.
const std::vector<std::string> kScriptSlots = {"orbit {} 0",
                                               "orbit 0 {}",
                                               "look-at {} 0 0 1 1 1",
                                               "look-at 0 {} 0 1 1 1",
                                               "look-at 0 0 {} 1 1 1",
                                               "look-at 0 0 0 {} 1 1",
                                               "look-at 0 0 0 1 {} 1",
                                               "look-at 0 0 0 1 1 {}",
                                               "zoom {}",
                                               "pan {} 0",
                                               "pan 0 {}",
                                               "iso {}",
                                               "wait rays {}",
                                               "wait time {}"};

std::string script_fill(const std::string& slot, const std::string& value) {
    std::string line = slot;
    return line.replace(line.find("{}"), 2, value);
}

// The message of the error parsing `line`, or "" when it parsed.
std::string error_of(const std::string& line) {
    try {
        parse_script(line, "s.txt");
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

TEST(ScriptNumbers, NoSlotTakesANonNumber) {
    int tried = 0;
    for (const std::string& slot : kScriptSlots)
        for (const char* bad : {"nan", "-nan", "NaN", "inf", "-inf", "infinity", "1e999", "-1e999",
                                "0x10", "5abc", "1e", "--1", "+-1", "1,5"}) {
            const std::string line = script_fill(slot, bad);
            const std::string command = line.substr(0, line.find(' '));
            const std::string e = error_of(line);
            EXPECT_EQ(e.rfind("s.txt:1: " + command + ": expected ", 0), 0u) << line << ": " << e;
            EXPECT_NE(e.find(bad), std::string::npos) << line << ": " << e;
            ++tried;
        }
    EXPECT_EQ(tried, 14 * 14);
}

TEST(ScriptNumbers, EverySlotHasARange) {
    struct Case {
        std::string line;
        bool ok;
    };
    const std::vector<Case> cases = {
        {"orbit 1e300 0", false},
        {"orbit 0 -1e300", false},
        {"orbit 1000001 0", false},
        {"orbit 1e6 -1e6", true},
        {"look-at 1e300 0 0 1 1 1", false},
        {"look-at 0 0 0 1 1 2e6", false},
        {"look-at 0 0 0 0 0 0", false},
        {"look-at 5 5 5 5 5 5", false},
        {"look-at 1000 0 0 1000.01 0 0", false},
        {"look-at 0 0 0 0 0 1", true},
        {"zoom 0", false},
        {"zoom -2", false},
        {"zoom 1e-300", false},
        {"zoom 1e300", false},
        {"zoom 1e-7", false},
        {"zoom 1e7", false},
        {"zoom 1e-6", true},
        {"zoom 1e6", true},
        {"pan 1001 0", false},
        {"pan 0 -1e300", false},
        {"pan -1000 1000", true},
        {"iso 1e300", true},
        {"iso -1e300", true},
        {"wait rays -5", false},
        {"wait rays 2.5", false},
        {"wait rays 1e300", false},
        {"wait rays 1e15", true},
        {"wait time -1", false},
        {"wait time 1e300", false},
        {"wait time 0", true},
    };
    for (const Case& c : cases) {
        const std::string e = error_of(c.line);
        EXPECT_EQ(e.empty(), c.ok) << c.line << ": " << e;
        if (!c.ok) {
            EXPECT_EQ(e.find('\n'), std::string::npos) << e;
        }
    }
}

TEST(ScriptNumbers, ErrorsQuoteABoundedPartOfTheLine) {
    const std::string huge(5 << 20, '7');
    const std::vector<std::string> lines = {"zoom " + huge + "x", huge + "x", "snapshot a/" + huge,
                                            "orbit 1 " + huge, "zoom \x1b[2J"};
    for (const std::string& line : lines) {
        const std::string e = error_of(line);
        ASSERT_FALSE(e.empty()) << line.substr(0, 40);
        EXPECT_LT(e.size(), 400u) << e.substr(0, 200);
        EXPECT_EQ(e.find('\x1b'), std::string::npos) << e;
    }
}

TEST(ScriptNumbers, SnapshotNamesAreOneShortPrintableName) {
    for (const std::string& bad :
         std::vector<std::string>{"a/b", "/abs", std::string(201, 'n'), "a\x01"})
        EXPECT_NE(error_of("snapshot " + bad), "") << bad;
    EXPECT_EQ(error_of("snapshot " + std::string(200, 'n')), "");
}

TEST(ScriptNumbers, ScriptFilesMustBeRegularFiles) {
    const auto dir = test::scratch_dir("script_files");
    std::filesystem::create_directory(dir / "folder");
    std::ofstream(dir / "ok.txt") << "zoom 2\nquit\n";
    for (const std::filesystem::path& p : {dir / "folder", std::filesystem::path("/dev/zero")}) {
        try {
            load_script(p);
            ADD_FAILURE() << "accepted " << p;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(p.string() + ": --script: ", 0), 0u) << e.what();
        }
    }
    EXPECT_EQ(load_script(dir / "ok.txt").size(), 2u);
}

}  // namespace
}  // namespace isowall
