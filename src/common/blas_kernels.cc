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

// How wide OpenBLAS's kernels for `core` are (OpenBLAS's own names, as
// openblas_get_corename() reports them, lower case): 2 AVX-512, 1 AVX2,
// 0 older or unknown.
int CoreVectorWidth(const std::string& core) {
  static const char* const kAvx512Cores[] = {"skylakex", "cooperlake",
                                             "sapphirerapids"};
  static const char* const kAvx2Cores[] = {"haswell", "zen"};
  for (const char* name : kAvx512Cores) {
    if (core == name) return 2;
  }
  for (const char* name : kAvx2Cores) {
    if (core == name) return 1;
  }
  return 0;
}

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(c));
  return text;
}

// The core OPENBLAS_CORETYPE asks for, "" when it is unset or empty (then
// OpenBLAS picks from its table).
std::string CoreTypeFromEnvironment() {
  const char* core = std::getenv("OPENBLAS_CORETYPE");
  return core != nullptr ? std::string(core) : std::string();
}

}  // namespace

bool OpenBlasCoreIsWeaker(const std::string& loaded,
                          const std::string& preferred) {
  return CoreVectorWidth(Lower(loaded)) < CoreVectorWidth(Lower(preferred));
}

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
  if (!CoreTypeFromEnvironment().empty()) return;
  const std::string loaded = LoadedOpenBlasCore();
  const std::string preferred = PreferredOpenBlasCore();
  if (loaded.empty() || !OpenBlasCoreIsWeaker(loaded, preferred)) return;
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
  const std::string preferred = PreferredOpenBlasCore();
  const std::string forced = CoreTypeFromEnvironment();
  if (!forced.empty() && OpenBlasCoreIsWeaker(loaded, preferred)) {
    // UseFastestBlasKernels leaves a core the user set alone.
    return "OpenBLAS (" + loaded + " kernels, as OPENBLAS_CORETYPE=" + forced +
           " asks; this CPU runs " + preferred +
           "'s: unset it or set that, for faster float32)";
  }
  return "OpenBLAS (" + loaded + " kernels)";
}

}  // namespace m2d
