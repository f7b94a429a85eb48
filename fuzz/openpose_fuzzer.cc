// fuzz: an OpenPose --write_json folder. The input is split at each line
// holding only "----" into up to 8 per-frame files, so the fuzzer can vary
// the frame count and mix good and bad frames.
#include <sys/stat.h>

#include <filesystem>

#include "fuzz/fuzz_support.h"
#include "motion/clip_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  const fs::path folder = m2d::fuzz::ScratchPath("_openpose");
  fs::remove_all(folder);
  fs::create_directories(folder);
  const std::string text(reinterpret_cast<const char*>(data), size);
  size_t begin = 0;
  for (int frame = 0; frame < 8 && begin <= text.size(); ++frame) {
    size_t end = text.find("\n----\n", begin);
    if (frame == 7 || end == std::string::npos) end = text.size();
    char name[64];
    std::snprintf(name, sizeof(name), "video_%012d_keypoints.json", frame);
    std::ofstream((folder / name).string(), std::ios::binary)
        << text.substr(begin, end - begin);
    begin = end + 6;
  }
  m2d::fuzz::ExpectResultOrNamedError([&] {
    m2d::ReadOpenPoseFolder(folder.string(), m2d::DetectionReadOptions());
  });
  return 0;
}
