#include "calib/serial_sparse_algebra.hpp"

#include <omp.h>

namespace omnivert::calib::internal {

SerialSparseAlgebra::SerialSparseAlgebra() : before_(omp_get_max_threads()) {
  omp_set_num_threads(1);
}

SerialSparseAlgebra::~SerialSparseAlgebra() { omp_set_num_threads(before_); }

}  // namespace omnivert::calib::internal
