// fuzz: a YAML settings file, read both as a training config (every section
// inline, as checkpoints embed it; a section naming a file reads that file)
// and as `mimic2d fit --config` options.
#include "fit/fit_config.h"
#include "fuzz/fuzz_support.h"
#include "rl/train_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = m2d::fuzz::WriteInput(data, size, ".yaml");
  const std::string text(reinterpret_cast<const char*>(data), size);
  m2d::fuzz::ExpectResultOrNamedError(
      [&] { m2d::LoadTrainConfigText(text, path); });
  m2d::fuzz::ExpectResultOrNamedError([&] { m2d::ReadFitOptions(path); });
  return 0;
}
