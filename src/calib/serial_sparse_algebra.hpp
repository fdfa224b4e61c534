#pragma once
// Ceres factors the batch problems' normal equations with CHOLMOD, which runs parts of its
// supernodal factorisation on OpenMP threads: a team of its compile-time
// CHOLMOD_OMP_NUM_THREADS (4 in Debian's build), asked for in a num_threads clause that
// omp_set_num_threads() does not override. The calibration already runs its own work side by
// side (--threads: the refinement beside the filter's noise check), so on top of those
// CHOLMOD's threads oversubscribe the cores and spend their time waiting on each other. While
// an object of this class lives, the calling thread has no active OpenMP levels (in libgomp a
// per-thread setting), so the solves it starts run on it alone; the results are the same to
// the bit (CHOLMOD's loops split rows, not sums).
// Test SerialSparseAlgebra.ARegionAskingForFourThreadsRunsOnOne checks that no team is started.

namespace omnivert::calib::internal {

class SerialSparseAlgebra {
 public:
  SerialSparseAlgebra();
  ~SerialSparseAlgebra();
  SerialSparseAlgebra(const SerialSparseAlgebra&) = delete;
  SerialSparseAlgebra& operator=(const SerialSparseAlgebra&) = delete;

 private:
  int before_;  // the calling thread's OpenMP max-active-levels, restored at the end
};

}  // namespace omnivert::calib::internal
