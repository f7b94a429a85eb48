// fuzz: a checkpoint as `mimic2d eval/render` load it: the embedded config
// rebuilds the networks, then the archive's tensors are read into them.
// Every mutation of the seed must be caught, by name, before LibTorch's
// archive reader sees a byte: that reader is not safe on damaged archives
// (docs/reliability.md), so checkpoints carry a checksum trailer. The seed
// is a tiny trained checkpoint (fuzz/make_seeds.sh).
#include "fuzz/fuzz_support.h"
#include "rl/torch_policy.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = m2d::fuzz::WriteInput(data, size, ".pt");
  m2d::fuzz::ExpectResultOrNamedError([&] { m2d::TorchPolicy policy(path); });
  return 0;
}
