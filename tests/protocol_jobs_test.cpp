// The scheduler's messages (job, job_done, region, landed, release), malformed: every value a
// receiver indexes or divides with is checked on the wire, and the error names the field. (The
// common faults, truncation, versions, trailing bytes and mutations, run over these messages too
// in protocol_malformed_test.cpp through samples().)
#include <gtest/gtest.h>

#include <limits>

#include "tests/protocol_test_util.h"

namespace isowall {
namespace {

using namespace protocol_testing;

struct JobFault {
    const char* field;
    void (*apply)(JobMsg&);
};

TEST(ProtocolJobs, JobFaultsThrowNamingTheField) {
    constexpr std::int32_t kIntMax = std::numeric_limits<std::int32_t>::max();
    const JobFault faults[] = {
        {"owner", [](JobMsg& m) { m.owner = 0; }},  // the master owns no tile
        {"owner", [](JobMsg& m) { m.owner = -3; }},
        {"band", [](JobMsg& m) { m.band = Band{2}; }},
        {"deliver", [](JobMsg& m) { m.deliver = 3; }},  // neither the owner nor the master
        {"deliver", [](JobMsg& m) { m.deliver = -1; }},
        {"band", [](JobMsg& m) { m.band = Band{255}; }},
        {"camera.eye", [](JobMsg& m) { m.view.camera.eye.x = kNaN; }},
        {"view.width", [](JobMsg& m) { m.view.width = 0; }},
        {"rect", [](JobMsg& m) { m.rect.x = -1; }},
        {"rect", [](JobMsg& m) { m.rect.y = -1; }},
        {"rect", [](JobMsg& m) { m.rect.width = 0; }},  // an empty job has nothing to cast
        {"rect", [](JobMsg& m) { m.rect.height = -1; }},
        {"rect",
         [](JobMsg& m) {
             m.rect = {1601, 0, 320, 240};
         }},  // one past the right
        {"rect",
         [](JobMsg& m) {
             m.rect = {0, 841, 320, 240};
         }},  // one past the bottom
        // x + width wraps around in 32 bits and would pass a naive check
        {"rect",
         [](JobMsg& m) {
             m.rect = {10, 0, kIntMax, 240};
         }},
        {"rect",
         [](JobMsg& m) {
             m.rect = {0, 10, 320, kIntMax};
         }},
    };
    for (const JobFault& f : faults) {
        JobMsg m = sample_job();
        f.apply(m);
        SCOPED_TRACE(testing::Message() << f.field << " in " << testing::PrintToString(m));
        expect_wire_error(Tag::job, encode(m), f.field);
    }
}

TEST(ProtocolJobs, JobDoneFaultsThrowNamingTheField) {
    constexpr double kNaN64 = std::numeric_limits<double>::quiet_NaN();
    JobDoneMsg m = sample_job_done();
    m.cpu_s = -0.5;
    expect_wire_error(Tag::job_done, encode(m), "cpu_s");
    m = sample_job_done();
    m.cpu_end_s = kNaN64;
    expect_wire_error(Tag::job_done, encode(m), "cpu_end_s");
    m = sample_job_done();
    m.start_s = std::numeric_limits<double>::infinity();
    expect_wire_error(Tag::job_done, encode(m), "start_s");
    m = sample_job_done();
    m.end_s = kNaN64;
    expect_wire_error(Tag::job_done, encode(m), "end_s");
}

struct RegionFault {
    const char* field;
    void (*apply)(RegionMsg&);
};

TEST(ProtocolJobs, RegionFaultsThrowNamingTheField) {
    const RegionFault faults[] = {
        {"layer", [](RegionMsg& m) { m.layer = kMaxSurfaces; }},
        {"rect", [](RegionMsg& m) { m.rect.width = 0; }},
        {"rect", [](RegionMsg& m) { m.rect.x = -1; }},
        {"rect",
         [](RegionMsg& m) {
             m.rect = {kMaxImageSide, 0, 3, 2};
         }},
        {"cpu_end_s", [](RegionMsg& m) { m.cpu_end_s = -1; }},
        {"cpu_end_s", [](RegionMsg& m) { m.cpu_end_s = kInf; }},
        {"rgba", [](RegionMsg& m) { m.rgba.pop_back(); }},
        {"rgba", [](RegionMsg& m) { m.rect.width = 4; }},  // sizes no longer match the pixels
        {"depth", [](RegionMsg& m) { m.depth.clear(); }},  // a region composites by depth
        {"depth", [](RegionMsg& m) { m.depth.push_back(1.0f); }},
    };
    for (const RegionFault& f : faults) {
        RegionMsg m = sample_region();
        f.apply(m);
        SCOPED_TRACE(f.field);
        expect_wire_error(Tag::region, encode(m), f.field);
    }
}

}  // namespace
}  // namespace isowall
