#pragma once
// An error that must end the process from where nothing can be thrown: a pager thread serving a
// memory fault (store/paged_voxels.h) or a check inside a mapped read (volume/octree_cache.cpp).
// By default one line on stderr ("isowall: error: WHAT") and exit status 1. The wall's ranks set
// their own handler, so the line names the rank and the job ends through the wall's failure path
// (exit 2, every rank ended), as any other error on a rank after start-up.
#include <functional>
#include <string>

namespace isowall {

// Replaces the handler (an empty function restores the default). The handler must not return.
void set_fatal_handler(std::function<void(const std::string& what)> handler);

// `what` through the handler; the process never goes on.
[[noreturn]] void end_with_error(const std::string& what);

}  // namespace isowall
