#include "extract/group_sink.h"

namespace isowall {

void TeeSink::begin(const FrameView& view) {
    for (GroupSink* s : sinks_) s->begin(view);
}

void TeeSink::add(const Group& group) {
    for (GroupSink* s : sinks_) s->add(group);
}

double TeeSink::present() {
    double seconds = 0;
    for (GroupSink* s : sinks_) seconds += s->present();
    return seconds;
}

bool TeeSink::present_async() {
    for (GroupSink* s : sinks_)
        if (!s->present_async()) s->present();
    return true;
}

bool TeeSink::presented(bool wait) {
    bool all = true;
    for (GroupSink* s : sinks_) all = s->presented(wait) && all;
    return all;
}

}  // namespace isowall
