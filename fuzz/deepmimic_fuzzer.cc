// fuzz: a DeepMimic motion file for the humanoid skeleton, as
// `mimic2d clip from-motion` reads it.
#include <memory>

#include "fuzz/fuzz_support.h"
#include "motion/motion_io.h"
#include "motion/skeleton.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto skeleton = std::make_shared<const m2d::Skeleton>(
      m2d::LoadSkeleton(MIMIC2D_SOURCE_DIR "/assets/skeletons/humanoid.yaml"));
  const std::string path = m2d::fuzz::WriteInput(data, size, ".txt");
  m2d::fuzz::ExpectResultOrNamedError(
      [&] { m2d::ReadDeepMimicMotion(path, skeleton); });
  return 0;
}
