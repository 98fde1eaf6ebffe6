# isowall_remote_view: the extraction server (server_session.cpp: a client's requests, levels of
# detail and cached groups; view_server.cpp: connections and their threads; server_access.cpp:
# tokens, loopback and what an address off loopback needs) and the client
# (client_frames.cpp: drawing and the timeline; view_client.cpp: its connection).
add_library(isowall_remote_view
    ${CMAKE_CURRENT_LIST_DIR}/server_session.cpp ${CMAKE_CURRENT_LIST_DIR}/lod_choice.cpp
    ${CMAKE_CURRENT_LIST_DIR}/view_server.cpp
    ${CMAKE_CURRENT_LIST_DIR}/tcp_channel.cpp ${CMAKE_CURRENT_LIST_DIR}/server_access.cpp
    ${CMAKE_CURRENT_LIST_DIR}/shared_session.cpp ${CMAKE_CURRENT_LIST_DIR}/server_refusal.cpp
    ${CMAKE_CURRENT_LIST_DIR}/client_frames.cpp ${CMAKE_CURRENT_LIST_DIR}/view_client.cpp)
target_include_directories(isowall_remote_view PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(isowall_remote_view
    PUBLIC isowall_engine isowall_renderer isowall_remote_codec isowall_remote_net PRIVATE isowall_warnings)
