# isowall_remote_net: TCP for `isowall serve` / `isowall view` (remote/net/): sockets with
# timeouts, HOST:PORT endpoints, framed connections and the emulated link's token bucket. POSIX
# sockets, and TLS through OpenSSL (tls.cpp).
add_library(isowall_remote_net
    ${CMAKE_CURRENT_LIST_DIR}/net/socket.cpp ${CMAKE_CURRENT_LIST_DIR}/net/endpoint.cpp
    ${CMAKE_CURRENT_LIST_DIR}/net/token_bucket.cpp ${CMAKE_CURRENT_LIST_DIR}/net/connection.cpp
    ${CMAKE_CURRENT_LIST_DIR}/net/tls.cpp ${CMAKE_CURRENT_LIST_DIR}/net/tcp_progress.cpp)
target_include_directories(isowall_remote_net PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(isowall_remote_net PUBLIC isowall_remote_proto Threads::Threads
    PRIVATE OpenSSL::SSL isowall_warnings)
# tcp_progress.cpp reads the kernel's tcp_info (linux/tcp.h), which clashes with glibc's
# netinet/tcp.h in the sockets' unity file.
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/net/tcp_progress.cpp
    PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
