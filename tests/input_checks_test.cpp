// The shared gates every input goes through: bounded quoting in errors, the number rule, small
// input files. Each table is a class of hostile input tried against every entry point it has.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/number.h"
#include "files/input_file.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

// `text` in double quotes, built piece by piece: GCC 12 warns falsely (-Wrestrict) on
// "literal" + std::string.
std::string q(const std::string& text) {
    std::string out = "\"";
    out += text;
    out += '"';
    return out;
}

TEST(Quote, BoundsEscapesAndNeverCutsACharacter) {
    struct Case {
        std::string text, want;
    };
    const std::string s60(60, 'a'), s61(61, 'a');
    const std::vector<Case> cases = {
        {"", "\"\""},
        {"abc", "\"abc\""},
        {s60, q(s60)},
        {s61, q(s60 + "...")},
        {std::string(5 << 20, 'x'), q(std::string(60, 'x') + "...")},
        {"a\nb", "\"a\\x0Ab\""},
        {"\x1b[31mred", "\"\\x1B[31mred\""},
        {std::string("nul\0byte", 8), "\"nul\\x00byte\""},
        {"\x7f", "\"\\x7F\""},
        // C1 controls (0x9B is a terminal's CSI) and bytes that are not UTF-8 are escaped too;
        // valid characters are kept.
        {"a\xc2\x9b"
         "31m",
         "\"a\\xC2\\x9B31m\""},
        {"\x9b"
         "31m\xff",
         "\"\\x9B31m\\xFF\""},
        {"\xc0\xaf", "\"\\xC0\\xAF\""},           // an overlong '/'
        {"\xed\xa0\x80", "\"\\xED\\xA0\\x80\""},  // a surrogate
        {"\xe2\x82", "\"\\xE2\\x82\""},           // cut short
        {"caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x99\x82",
         "\"caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x99\x82\""},
        // 59 ASCII then a 2-byte character: the character is kept whole, not split.
        {std::string(59, 'a') + "\xc3\xa9" + "zz", q(std::string(59, 'a') + "\xc3\xa9...")},
    };
    for (const Case& c : cases)
        EXPECT_EQ(quote(c.text), c.want) << "input of " << c.text.size() << " bytes";
}

TEST(Quote, InputErrorBoundsEveryPartWhoeverBuiltIt) {
    const std::string huge(5 << 20, 'z');
    const std::vector<InputError> errors = {
        InputError(huge, "field", "message"),
        InputError("w.txt", huge, "message"),
        InputError("w.txt", "field", "got " + huge),
        InputError("a\nb", "f\r", "m\n"),
    };
    for (const InputError& e : errors) {
        const std::string what = e.what();
        EXPECT_LT(what.size(), 700u) << what.substr(0, 100);
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_EQ(what.find('\r'), std::string::npos) << what;
    }
    // A long path keeps its end: the file's name.
    const std::string path = std::string(300, 'd') + "/wall.toml";
    EXPECT_NE(std::string(InputError(path, "tiles", "missing").what()).find("/wall.toml: tiles"),
              std::string::npos);
}

TEST(Numbers, ParseRefusesEverythingButOneFiniteNumber) {
    for (const char* bad : {"",     "+",        "-",     "nan",    "NaN",  "-nan", "inf",  "-inf",
                            "+inf", "infinity", "1e999", "-1e999", "0x10", "5abc", " 5",   "5 ",
                            "+-5",  "--5",      "1,5",   "1e",     ".",    "1..2", "five", "\t1"})
        EXPECT_FALSE(parse_number(bad).has_value()) << '"' << bad << '"';
    const std::vector<std::pair<const char*, double>> good = {
        {"0", 0},    {"-0", 0},        {"+5", 5},   {"1e3", 1000},    {"2.5", 2.5},
        {".5", 0.5}, {"-1e-3", -1e-3}, {"010", 10}, {"1e300", 1e300}, {"007.50", 7.5}};
    for (const auto& [text, value] : good) {
        ASSERT_TRUE(parse_number(text).has_value()) << text;
        EXPECT_DOUBLE_EQ(*parse_number(text), value) << text;
    }
}

TEST(Numbers, EveryRangeRefusesNonFiniteAndOutOfRange) {
    struct Named {
        const char* name;
        NumberRange range;
    };
    const Named ranges[] = {{"any", limits::kAnyFinite},
                            {"angle", limits::kAngleDeg},
                            {"zoom", limits::kZoom},
                            {"pan", limits::kPan},
                            {"coord", limits::kCoordinate},
                            {"percent", limits::kPercent},
                            {"seconds", limits::kSeconds},
                            {"wait", limits::kWaitSeconds},
                            {"rays", limits::kRayCount},
                            {"cutoff", limits::kCutoffDeg},
                            {"foldback", limits::kFoldbackDeg},
                            {"cells", limits::kCellCount}};
    int tried = 0;
    for (const Named& n : ranges) {
        for (const char* bad : {"nan", "inf", "-inf", "1e999", "", "x"}) {
            EXPECT_NE(number_problem(bad, n.range), "") << n.name << " " << bad;
            ++tried;
        }
        char above[64], below[64];
        std::snprintf(above, sizeof(above), "%.17g", n.range.hi + std::abs(n.range.hi) + 1);
        std::snprintf(below, sizeof(below), "%.17g", n.range.lo - std::abs(n.range.lo) - 1);
        if (n.range.hi < limits::kMaxFinite / 4) {
            EXPECT_NE(number_problem(above, n.range), "") << n.name;
        }
        if (n.range.lo > -limits::kMaxFinite / 4) {
            EXPECT_NE(number_problem(below, n.range), "") << n.name;
        }
        char lo[64], hi[64];
        std::snprintf(lo, sizeof(lo), "%.17g", n.range.lo);
        std::snprintf(hi, sizeof(hi), "%.17g", n.range.hi);
        EXPECT_EQ(number_problem(hi, n.range), "") << n.name;
        EXPECT_EQ(number_problem(lo, n.range).empty(), !n.range.lo_open) << n.name;
        tried += 4;
    }
    EXPECT_GT(tried, 100);
    EXPECT_NE(number_problem("2.5", limits::kRayCount), "");  // integers only
    // Past the end by one, though a double rounds it onto the end (2^53 + 1 -> 2^53).
    EXPECT_EQ(number_problem("9007199254740992", limits::kRayCount), "");
    EXPECT_EQ(number_problem("9007199254740993", limits::kRayCount),
              "expected an integer in [0, 9007199254740992], got \"9007199254740993\"");
    EXPECT_NE(number_problem("+2147483648", limits::kCellCount), "");
    EXPECT_EQ(number_problem("-5", limits::kRayCount),
              "expected an integer in [0, 9007199254740992], got \"-5\"");
    EXPECT_EQ(number_problem("nan", limits::kAnyFinite), "expected a finite number, got \"nan\"");
}

TEST(Numbers, CheckedNumberNamesSourceAndField) {
    try {
        checked_number("1e-300", limits::kZoom, "demo.txt:3", "zoom");
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(),
                     "demo.txt:3: zoom: expected a number in [1e-06, 1e+06], got "
                     "\"1e-300\"");
    }
}

TEST(InputFile, RefusesFoldersDevicesMissingAndOversized) {
    const auto dir = test::scratch_dir("input_file");
    std::ofstream(dir / "ok.txt") << "hello";
    std::ofstream(dir / "big.txt") << std::string(2000, 'b');
    std::filesystem::create_directory(dir / "folder");
    struct Case {
        std::filesystem::path path;
        const char* mentions;
    };
    const Case cases[] = {{dir / "folder", "is a folder"},
                          {"/dev/zero", "not a regular file"},
                          {"/dev/null", "not a regular file"},
                          {dir / "missing.txt", "no such file"},
                          {dir / "big.txt", "expected at most 1000"}};
    for (const Case& c : cases) {
        try {
            read_input_file(c.path, "--script", 1000);
            ADD_FAILURE() << "accepted " << c.path;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind(c.path.string() + ": --script: ", 0), 0u) << what;
            EXPECT_NE(what.find(c.mentions), std::string::npos) << what;
        }
    }
    EXPECT_EQ(read_input_file(dir / "ok.txt", "--script", 1000), "hello");
}

}  // namespace
}  // namespace isowall
