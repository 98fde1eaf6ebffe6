# The group codecs: how a group travels from the extraction server to the client.
find_package(meshoptimizer REQUIRED)
# PkgConfig::ZSTD: found in store/CMakeLists.txt (the stores use it too).

add_library(isowall_remote_codec group_codec.cpp compact_mesh.cpp cell_codec.cpp cell_units.cpp
    encoding_choice.cpp)
target_include_directories(isowall_remote_codec PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(isowall_remote_codec
    PUBLIC isowall_core isowall_wire isowall_extract
    PRIVATE isowall_warnings meshoptimizer::meshoptimizer PkgConfig::ZSTD)

# Bytes a triangle, encode and decode time of each encoding on one frame's groups (not a test).
add_executable(isowall_bench_codec bench_codec.cpp)
target_link_libraries(isowall_bench_codec PRIVATE isowall_remote_codec isowall_extract isowall_warnings)
