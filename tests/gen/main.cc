// The gen tests train networks: pick OpenBLAS's fast kernels before anything
// else (common/blas_kernels.h), then run GoogleTest.
#include <gtest/gtest.h>

#include "common/blas_kernels.h"

int main(int argc, char** argv) {
  m2d::UseFastestBlasKernels(argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
