// common: choice of the BLAS kernels LibTorch's matrix products run on.
//
// OpenBLAS (Debian's libopenblas0-*, selected as libblas.so.3) picks its
// kernels from a table of CPU models when it loads. Virtual machines often
// report a generic model ("Intel Xeon Processor"), and OpenBLAS then falls
// back to its oldest SSE3 ("Prescott") kernels: the PPO update ran 4.4x
// slower than with its AVX-512 kernels on the development machine
// (docs/benchmarks.md). AVX2 kernels on an AVX-512 CPU are moved up too:
// on an AMD Zen 5 OpenBLAS's AVX-512 kernels trained float32 1.3-1.4x
// faster than its "Haswell" ones. The override, OPENBLAS_CORETYPE, is only
// read at load time, so it has to be set before the program starts; a value
// the user set is left alone.
#ifndef MIMIC2D_COMMON_BLAS_KERNELS_H_
#define MIMIC2D_COMMON_BLAS_KERNELS_H_

#include <string>

namespace m2d {

// The OpenBLAS core type best suited to this CPU's instruction sets
// ("SkylakeX" with AVX-512, "Haswell" with AVX2 + FMA), or "" when the
// CPU has neither.
std::string PreferredOpenBlasCore();

// Whether OpenBLAS's `loaded` kernels use narrower vectors than the
// `preferred` ones (core names as OpenBLAS spells them, any case; AVX-512
// cores > AVX2 cores ("Haswell", "Zen") > any other, e.g. "Prescott").
bool OpenBlasCoreIsWeaker(const std::string& loaded,
                          const std::string& preferred);

// OpenBLAS's kernel choice in this process (e.g. "SkylakeX"), or "" when
// the BLAS in use is not OpenBLAS.
std::string LoadedOpenBlasCore();

// Call first thing in main(). When OpenBLAS is the BLAS in use, chose
// kernels weaker than PreferredOpenBlasCore(), and OPENBLAS_CORETYPE is
// unset, re-executes the program once with OPENBLAS_CORETYPE set; returns
// (doing nothing) otherwise, or if the re-execution fails.
void UseFastestBlasKernels(char** argv);

// The file (symbolic links resolved) of the shared library that provides
// sgemm_, the single-precision product LibTorch's linear layers call, in
// this process; "" when no library does. Two libraries may export it (Ceres
// brings ATLAS's libf77blas.so.3): the one loaded first wins.
std::string SgemmLibraryPath();

// One line for logs, e.g. "OpenBLAS (SkylakeX kernels)", or what provides
// sgemm_ instead; it says so when OPENBLAS_CORETYPE holds OpenBLAS to
// weaker kernels than the CPU runs.
std::string DescribeBlas();

}  // namespace m2d

#endif  // MIMIC2D_COMMON_BLAS_KERNELS_H_
