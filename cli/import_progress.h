#pragma once
// The progress of writing a store (`isowall import`, or a store re-chunked into the cache before
// it pages): one line redrawn in place on a terminal; elsewhere (a log, CI) a line at each
// quarter, so a long run says how far it is and how long is left.
#include <string>

#include "core/util.h"
#include "store/store_writer.h"

namespace isowall {

class ImportProgressBar {
  public:
    // `label` starts each line ("import", "re-chunk"); nothing is printed when `quiet`.
    ImportProgressBar(std::string label, bool quiet);
    void update(const store::ImportProgress& p);
    void finish();  // ends the line a terminal redraws

  private:
    std::string label_;
    bool quiet_, tty_;
    int last_quarter_ = -1;
    Stopwatch sw_;
};

}  // namespace isowall
