#include "calib/serial_sparse_algebra.hpp"

#include <omp.h>

namespace omnivert::calib::internal {

SerialSparseAlgebra::SerialSparseAlgebra() : before_(omp_get_max_active_levels()) {
  omp_set_max_active_levels(0);
}

SerialSparseAlgebra::~SerialSparseAlgebra() { omp_set_max_active_levels(before_); }

}  // namespace omnivert::calib::internal
