# isowall_remote_web: HTTP and WebSocket on one port for `isowall serve --http`, through
# Debian's websocketpp 0.8.2 over standalone asio. websocketpp does not compile as C++20, so this
# target is C++17 and its header (web_server.h) includes neither library; the C++20 side
# (isowall_remote_http below) sees only callbacks and bytes.
find_path(WEBSOCKETPP_INCLUDE_DIR websocketpp/server.hpp REQUIRED)
find_path(ASIO_INCLUDE_DIR asio.hpp REQUIRED)

add_library(isowall_remote_web ${CMAKE_CURRENT_LIST_DIR}/web_server.cpp
    ${CMAKE_CURRENT_LIST_DIR}/web_endpoint.cpp)
set_target_properties(isowall_remote_web PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON)
target_include_directories(isowall_remote_web PUBLIC ${PROJECT_SOURCE_DIR}
    PRIVATE ${WEBSOCKETPP_INCLUDE_DIR} ${ASIO_INCLUDE_DIR})
target_compile_definitions(isowall_remote_web PRIVATE ASIO_STANDALONE)
target_link_libraries(isowall_remote_web PUBLIC Threads::Threads
    PRIVATE OpenSSL::SSL isowall_warnings)

# isowall_remote_http (C++20): the WebSocket as a MessageChannel (web_channel.cpp), the HTTP
# routes (web_routes.cpp, pure), the front end that joins them to a ViewServer (http_front.cpp),
# and the page's files, embedded at build time from web/dist/ (embed_assets.cmake).
file(GLOB_RECURSE ISOWALL_WEB_DIST CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/web/dist/*)
set(ISOWALL_WEB_ASSETS_CPP ${CMAKE_CURRENT_BINARY_DIR}/web_assets.cpp)
add_custom_command(OUTPUT ${ISOWALL_WEB_ASSETS_CPP}
    COMMAND ${CMAKE_COMMAND} -DROOT=${PROJECT_SOURCE_DIR}/web/dist -DOUT=${ISOWALL_WEB_ASSETS_CPP}
        -P ${CMAKE_CURRENT_LIST_DIR}/embed_assets.cmake
    DEPENDS ${ISOWALL_WEB_DIST} ${CMAKE_CURRENT_LIST_DIR}/embed_assets.cmake
    COMMENT "Embedding web/dist/ into web_assets.cpp" VERBATIM)

add_library(isowall_remote_http
    ${CMAKE_CURRENT_LIST_DIR}/web_channel.cpp ${CMAKE_CURRENT_LIST_DIR}/web_routes.cpp
    ${CMAKE_CURRENT_LIST_DIR}/http_front.cpp ${ISOWALL_WEB_ASSETS_CPP})
target_include_directories(isowall_remote_http PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(isowall_remote_http PUBLIC isowall_remote_view isowall_remote_web
    PRIVATE isowall_warnings)
