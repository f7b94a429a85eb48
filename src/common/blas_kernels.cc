#include "common/blas_kernels.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cctype>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace m2d {
namespace {

// OpenBLAS core names whose kernels use AVX2 or AVX-512 (OpenBLAS's own
// names, as openblas_get_corename() reports them, lower case).
bool IsVectorCore(const std::string& core) {
  static const char* const kVectorCores[] = {
      "haswell", "skylakex", "cooperlake", "sapphirerapids", "zen"};
  for (const char* name : kVectorCores) {
    if (core == name) return true;
  }
  return false;
}

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(c));
  return text;
}

}  // namespace

std::string PreferredOpenBlasCore() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return "Haswell";
  return "";
}

std::string LoadedOpenBlasCore() {
  // Looked up at run time: the program links libblas.so.3, whichever
  // implementation the system's alternatives point it to.
  using CoreNameFunction = char* (*)();
  auto core_name = reinterpret_cast<CoreNameFunction>(
      dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (core_name == nullptr) return "";
  const char* name = core_name();
  return name != nullptr ? std::string(name) : std::string();
}

void UseFastestBlasKernels(char** argv) {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;
  const std::string loaded = LoadedOpenBlasCore();
  const std::string preferred = PreferredOpenBlasCore();
  if (loaded.empty() || preferred.empty() || IsVectorCore(Lower(loaded)))
    return;
  setenv("OPENBLAS_CORETYPE", preferred.c_str(), /*overwrite=*/1);
  execv("/proc/self/exe", argv);
  // Only reached when exec failed: carry on with the slower kernels.
  std::fprintf(stderr,
               "warning: could not restart with OPENBLAS_CORETYPE=%s; matrix "
               "products use OpenBLAS's %s kernels\n",
               preferred.c_str(), loaded.c_str());
}

std::string SgemmLibraryPath() {
  void* sgemm = dlsym(RTLD_DEFAULT, "sgemm_");
  Dl_info info;
  if (sgemm == nullptr || dladdr(sgemm, &info) == 0 ||
      info.dli_fname == nullptr)
    return "";
  char resolved[PATH_MAX];
  return realpath(info.dli_fname, resolved) != nullptr
             ? std::string(resolved)
             : std::string(info.dli_fname);
}

std::string DescribeBlas() {
  const std::string loaded = LoadedOpenBlasCore();
  const std::string sgemm = SgemmLibraryPath();
  if (!sgemm.empty() && Lower(sgemm).find("openblas") == std::string::npos)
    return "sgemm_ from " + sgemm +
           ", not OpenBLAS (slow; see m2d_blas_first in CMakeLists.txt)";
  if (loaded.empty()) return "not OpenBLAS (install libopenblas0-openmp)";
  return "OpenBLAS (" + loaded + " kernels)";
}

}  // namespace m2d
