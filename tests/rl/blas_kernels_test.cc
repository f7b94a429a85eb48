// The PPO update's speed rests on OpenBLAS running its AVX2/AVX-512 kernels
// (common/blas_kernels.h); this binary's main() asks for them.
#include "common/blas_kernels.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cctype>
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
  if (loaded.empty()) GTEST_SKIP() << "the BLAS in use is not OpenBLAS";
  const std::string preferred = PreferredOpenBlasCore();
  if (preferred.empty()) GTEST_SKIP() << "CPU has neither AVX2 nor AVX-512";
  const std::string core = Lower(loaded);
  EXPECT_TRUE(core == "haswell" || core == "skylakex" || core == "cooperlake" ||
              core == "sapphirerapids" || core == "zen")
      << "OpenBLAS runs its " << loaded << " kernels; this CPU supports "
      << preferred << " (" << DescribeBlas() << ")";
}

}  // namespace
}  // namespace m2d
