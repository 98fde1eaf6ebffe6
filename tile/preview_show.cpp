#include "tile/preview_show.h"

#include "core/preview.h"
#include "wall_protocol/protocol.h"

namespace isowall {

void PreviewShow::show(const Image& tile, std::uint64_t generation) {
    send_message(comm_, kMasterRank, PreviewMsg{make_preview(tile, generation, max_side_)});
}

}  // namespace isowall
