// fuzz: a reference bundle (2D views, cameras, optional truth and
// estimate), as `mimic2d train/eval/fit` read it.
#include "fuzz/fuzz_support.h"
#include "motion/bundle.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = m2d::fuzz::WriteInput(data, size, ".json");
  m2d::fuzz::ExpectResultOrNamedError([&] { m2d::ReadBundle(path); });
  return 0;
}
