// fuzz: a keypoint JSON file as `mimic2d clip` and `mimic2d fit` read it
// (our clip format or COCO-style detector output, detected from content).
#include "fuzz/fuzz_support.h"
#include "motion/clip_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = m2d::fuzz::WriteInput(data, size, ".json");
  m2d::fuzz::ExpectResultOrNamedError(
      [&] { m2d::ReadClipAuto(path, m2d::DetectionReadOptions()); });
  return 0;
}
