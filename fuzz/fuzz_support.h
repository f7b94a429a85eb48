// fuzz: libFuzzer targets for every reader of user input (docs/reliability.md).
// Shared by the targets: the fuzzer's bytes become a file, because users
// hand us files and the readers' errors name them; the contract is that a
// reader either returns or throws a named error (InputError, ConfigError).
// Anything else (another exception, a crash, a sanitizer report, an
// allocation beyond -rss_limit_mb) escapes and libFuzzer records it.
#ifndef MIMIC2D_FUZZ_FUZZ_SUPPORT_H_
#define MIMIC2D_FUZZ_FUZZ_SUPPORT_H_

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "common/error.h"

namespace m2d::fuzz {

// A per-process scratch path in shared memory (or $TMPDIR) ending in
// `suffix`: the same path every call, so files never pile up.
inline std::string ScratchPath(const std::string& suffix) {
  const char* shm = "/dev/shm";
  std::string dir = access(shm, W_OK) == 0 ? shm : "/tmp";
  return dir + "/m2d_fuzz_" + std::to_string(getpid()) + suffix;
}

inline std::string WriteInput(const uint8_t* data, size_t size,
                              const std::string& suffix) {
  const std::string path = ScratchPath(suffix);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data),
            static_cast<std::streamsize>(size));
  if (!out) {
    std::perror(path.c_str());
    std::abort();
  }
  return path;
}

// Runs `read`; a named error is the expected outcome for bad input.
template <typename Read>
void ExpectResultOrNamedError(Read read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const ConfigError&) {
  }
}

}  // namespace m2d::fuzz

#endif  // MIMIC2D_FUZZ_FUZZ_SUPPORT_H_
