// Harness: what a browser page says to the wall (master/wall_page.h: parse_page_message, JSON
// through nlohmann's parser, then a script line through parse_command). A message that parses
// is one the master may act on: a run line parses again as a command that is neither wait nor
// snapshot (a page must not stall the wall or name files), and hello and run carry their text.
#include <string>
#include <variant>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "master/wall_page.h"
#include "wall_spec/script.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using isowall::PageMessage;
    using isowall::fuzz::check;
    try {
        const PageMessage m =
            isowall::parse_page_message(isowall::fuzz::as_text(data, size), "page 1");
        check(size <= isowall::kMaxPageMessage, "a message within the size bound");
        if (m.kind == PageMessage::Kind::run) {
            const isowall::ScriptCommand c = isowall::parse_command(m.text, "page 1");
            check(!std::holds_alternative<isowall::WaitCmd>(c) &&
                      !std::holds_alternative<isowall::SnapshotCmd>(c),
                  "a page's line is neither wait nor snapshot");
        }
        if (m.kind == PageMessage::Kind::snapshot || m.kind == PageMessage::Kind::take)
            check(m.text.empty(), "snapshot and take carry no text");
    } catch (const isowall::InputError&) {
    }
    return 0;
}
