// --iso: one declaration for render, extract, wall and view, and one check whatever the source
// of the values (a volume file, the phantom, a served dataset).
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "app/program_cli.h"
#include "cli/iso_option.h"
#include "core/error.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

std::string error_of(const std::optional<double>& iso, const IsoSource& source) {
    try {
        checked_iso(iso, source);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(CliIso, ThePhantomDefaultsToItsSkinAFileHasNoDefault) {
    EXPECT_EQ(checked_iso(std::nullopt, {"phantom", true, 0, 255}), kPhantomSkinIso);
    const std::string e = error_of(std::nullopt, {"head.nhdr", false, 0, 255});
    EXPECT_NE(e.find("head.nhdr"), std::string::npos) << e;
    EXPECT_NE(e.find("--iso"), std::string::npos) << e;
    EXPECT_NE(e.find("an isovalue is required"), std::string::npos) << e;
}

TEST(CliIso, TheRangeIsInclusiveAndAnIsovalueOutsideItIsRefusedWithTheRange) {
    EXPECT_EQ(checked_iso(0.0, {"v", false, 0, 255}), 0.0);
    EXPECT_EQ(checked_iso(255.0, {"v", false, 0, 255}), 255.0);
    for (const double iso : {-0.5, 255.5}) {
        const std::string e = error_of(iso, {"dataset 'head'", false, 0, 255});
        EXPECT_NE(e.find("dataset 'head'"), std::string::npos) << e;
        EXPECT_NE(e.find("outside the value range [0, 255]"), std::string::npos) << e;
    }
    // The phantom's range applies to a given isovalue as to any other.
    EXPECT_FALSE(error_of(300.0, {"phantom", true, 0, 255}).empty());
}

TEST(CliIso, EverySubcommandThatDrawsDeclaresTheSameOption) {
    ProgramCli cli;
    for (const char* name : {"render", "extract", "wall", "view"}) {
        CLI::App* cmd = cli.app.get_subcommand(name);
        ASSERT_NE(cmd, nullptr) << name;
        const CLI::Option* iso = cmd->get_option("--iso");
        ASSERT_NE(iso, nullptr) << name;
        EXPECT_NE(iso->get_description().find("skin, 50"), std::string::npos)
            << name << ": " << iso->get_description();
    }
}

}  // namespace
}  // namespace isowall
