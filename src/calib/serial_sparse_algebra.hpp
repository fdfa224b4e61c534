#pragma once
// Ceres factors the batch problems' normal equations with CHOLMOD, which runs parts of its
// supernodal factorisation on OpenMP threads (as many as the machine has, by default). The
// calibration already runs its own work side by side (--threads: the refinement beside the
// filter's noise check), so on top of those CHOLMOD's threads oversubscribe the cores and spend
// their time waiting on each other (on 2 cores: a tenth of the hall tour's refinement in futex
// waits). While an object of this class lives, the solves the calling thread starts use one
// OpenMP thread; the results are the same to the bit (CHOLMOD's loops split rows, not sums).
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
