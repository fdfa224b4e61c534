#include "calib/serial_sparse_algebra.hpp"

#include <omp.h>

namespace omnivert::calib::internal {

// CHOLMOD asks for a fixed team (its compile-time CHOLMOD_OMP_NUM_THREADS, 4 in Debian's
// build) in a num_threads clause, which overrides omp_set_num_threads(). No active levels
// makes every parallel region this thread starts run on the thread alone; in libgomp the
// setting is the calling thread's (a thread started later begins with the default).
SerialSparseAlgebra::SerialSparseAlgebra() : before_(omp_get_max_active_levels()) {
  omp_set_max_active_levels(0);
}

SerialSparseAlgebra::~SerialSparseAlgebra() { omp_set_max_active_levels(before_); }

}  // namespace omnivert::calib::internal
