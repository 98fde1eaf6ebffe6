# isowall_remote_net: TCP for `isowall serve` / `isowall view` (remote/net/): connected streams
# with timeouts and a listener on standalone asio (one net thread, net_stream.h), TLS through
# asio::ssl with contexts checked through OpenSSL (tls.cpp), HOST:PORT endpoints, framed
# connections and the emulated link's token bucket. The same asio as the HTTP server's
# (remote/http/), in C++20 here: only websocketpp needs C++17.
find_path(ASIO_INCLUDE_DIR asio.hpp REQUIRED)
add_library(isowall_remote_net
    ${CMAKE_CURRENT_LIST_DIR}/net/socket.cpp ${CMAKE_CURRENT_LIST_DIR}/net/endpoint.cpp
    ${CMAKE_CURRENT_LIST_DIR}/net/token_bucket.cpp ${CMAKE_CURRENT_LIST_DIR}/net/connection.cpp
    ${CMAKE_CURRENT_LIST_DIR}/net/tls.cpp ${CMAKE_CURRENT_LIST_DIR}/net/tcp_progress.cpp)
target_include_directories(isowall_remote_net PUBLIC ${PROJECT_SOURCE_DIR}
    PRIVATE ${ASIO_INCLUDE_DIR})
target_compile_definitions(isowall_remote_net PRIVATE ASIO_STANDALONE)
target_link_libraries(isowall_remote_net PUBLIC isowall_remote_proto Threads::Threads
    PRIVATE OpenSSL::SSL isowall_warnings)
# tcp_progress.cpp reads the kernel's tcp_info (linux/tcp.h), which clashes with glibc's
# netinet/tcp.h (which asio includes) in the target's unity file.
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/net/tcp_progress.cpp
    PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
