// SerialSparseAlgebra (calib/serial_sparse_algebra.hpp): the parallel regions a thread starts
// under it run on that thread alone, even when they ask for a team in a num_threads clause
// as CHOLMOD's supernodal factorisation does; the thread's setting is restored after it.
#include <omp.h>

#include <thread>

#include <gtest/gtest.h>

#include "calib/serial_sparse_algebra.hpp"

namespace omnivert::calib::internal {
namespace {

// The team size of a region that asks for 4 threads, as CHOLMOD_OMP_NUM_THREADS does.
int team_asking_for_four() {
  int team = 0;
#pragma omp parallel num_threads(4)
  {
#pragma omp master
    team = omp_get_num_threads();
  }
  return team;
}

TEST(SerialSparseAlgebra, ARegionAskingForFourThreadsRunsOnOne) {
  ASSERT_EQ(team_asking_for_four(), 4);  // the runtime gives the team when allowed
  {
    const SerialSparseAlgebra serial;
    EXPECT_EQ(team_asking_for_four(), 1);
  }
  EXPECT_EQ(team_asking_for_four(), 4);  // restored
}

TEST(SerialSparseAlgebra, OnlyTheCallingThreadIsSerial) {
  const SerialSparseAlgebra serial;
  int other = 0;
  std::thread t([&other] { other = team_asking_for_four(); });
  t.join();
  EXPECT_EQ(other, 4);
  EXPECT_EQ(team_asking_for_four(), 1);
}

}  // namespace
}  // namespace omnivert::calib::internal
