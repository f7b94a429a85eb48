// fuzz: a BVH motion capture file (read through libassimp), as
// `mimic2d clip from-motion` reads it.
#include "fuzz/fuzz_support.h"
#include "motion/motion_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = m2d::fuzz::WriteInput(data, size, ".bvh");
  m2d::fuzz::ExpectResultOrNamedError(
      [&] { m2d::ReadBvhMotion(path, 0.056444); });
  return 0;
}
