// The PPO update's speed rests on OpenBLAS running its AVX2/AVX-512 kernels
// (common/blas_kernels.h); this binary's main() asks for them.
#include "common/blas_kernels.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cctype>
#include <cstdlib>
#include <string>

namespace m2d {
namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(c));
  return text;
}

TEST(BlasKernels, OpenBlasRunsTheKernelsTheCpuSupports) {
  // A matrix product makes sure the BLAS is loaded and initialized.
  torch::Tensor product = torch::ones({64, 64}).matmul(torch::ones({64, 64}));
  ASSERT_FLOAT_EQ(product[0][0].item<float>(), 64.0f);
  const std::string loaded = LoadedOpenBlasCore();
  ASSERT_FALSE(loaded.empty())
      << "the BLAS in use is not OpenBLAS (setup.sh installs "
         "libopenblas0-openmp)";
  const std::string preferred = PreferredOpenBlasCore();
  // A CPU with neither AVX2 nor AVX-512 has no faster kernels to ask for.
  if (preferred.empty()) return;
  const char* forced = std::getenv("OPENBLAS_CORETYPE");
  if (forced != nullptr && *forced != '\0' &&
      Lower(forced) != Lower(preferred)) {
    // A core the user set is left alone, and the log line says what it
    // costs when it is weaker.
    EXPECT_EQ(Lower(loaded), Lower(forced));
    EXPECT_EQ(OpenBlasCoreIsWeaker(loaded, preferred),
              DescribeBlas().find("unset it") != std::string::npos)
        << DescribeBlas();
    return;
  }
  EXPECT_FALSE(OpenBlasCoreIsWeaker(loaded, preferred))
      << "OpenBLAS runs its " << loaded << " kernels; this CPU supports "
      << preferred << " (" << DescribeBlas() << ")";
}

TEST(BlasKernels, AvxTwoKernelsAreWeakerOnAnAvx512Cpu) {
  EXPECT_TRUE(OpenBlasCoreIsWeaker("Prescott", "Haswell"));
  EXPECT_TRUE(OpenBlasCoreIsWeaker("Haswell", "SkylakeX"));
  EXPECT_TRUE(OpenBlasCoreIsWeaker("ZEN", "SkylakeX"));  // AVX-512 filed as Zen
  EXPECT_FALSE(OpenBlasCoreIsWeaker("Zen", "Haswell"));
  EXPECT_FALSE(OpenBlasCoreIsWeaker("SkylakeX", "SkylakeX"));
  EXPECT_FALSE(OpenBlasCoreIsWeaker("SapphireRapids", "SkylakeX"));
  EXPECT_FALSE(OpenBlasCoreIsWeaker("CooperLake", "Haswell"));
}

// This binary links Ceres (m2d_fit), which brings ATLAS's libf77blas.so.3
// with its own sgemm_: the link order must let OpenBLAS's win (CMakeLists,
// m2d_blas_first), or every linear layer runs 4x slower.
TEST(BlasKernels, LibTorchsMatrixProductsRunOnOpenBlas) {
  const std::string sgemm = SgemmLibraryPath();
  ASSERT_FALSE(sgemm.empty()) << "no library provides sgemm_";
  EXPECT_NE(Lower(sgemm).find("openblas"), std::string::npos)
      << "sgemm_ comes from " << sgemm;
}

}  // namespace
}  // namespace m2d
