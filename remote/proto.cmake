# isowall_remote_proto: the messages of `isowall serve` <-> `isowall view` and their framing on a
# byte stream (view_protocol.h, view_framing.h); pure, no sockets.
add_library(isowall_remote_proto
    ${CMAKE_CURRENT_LIST_DIR}/view_protocol.cpp
    ${CMAKE_CURRENT_LIST_DIR}/slot_list.cpp
    ${CMAKE_CURRENT_LIST_DIR}/view_framing.cpp ${CMAKE_CURRENT_LIST_DIR}/request_checks.cpp)
target_include_directories(isowall_remote_proto PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(isowall_remote_proto PUBLIC isowall_core isowall_wire isowall_extract PRIVATE isowall_warnings)
