#pragma once
// Work spread over threads, for the per-frame stages that do not depend on each other
// (reading and decoding images; lines and descriptors of a frame whose circle is known).

#include <cstddef>
#include <functional>

namespace omnivert {

// The number of threads to use for a requested count: `requested` itself when positive,
// else every core the machine reports (at least 1).
int resolve_threads(int requested);

// Calls fn(i, worker) for every i in [0, n), with worker in [0, threads): item i goes to
// worker i % threads, and each worker handles its items in increasing order on its own
// thread, so a caller may give each worker its own scratch state. threads <= 1 (or n <= 1)
// runs everything on the calling thread, in order. Returns when every call has returned; an
// exception thrown by a call is rethrown here (the one of the lowest item), after every
// worker has stopped.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t, int)>& fn);

}  // namespace omnivert
