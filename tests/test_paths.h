// tests: where the project's assets and the shared reference data live.
#ifndef MIMIC2D_TESTS_TEST_PATHS_H_
#define MIMIC2D_TESTS_TEST_PATHS_H_

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace m2d::testing {

inline std::string SourcePath(const std::string& relative) {
  return std::string(MIMIC2D_SOURCE_DIR) + "/" + relative;
}

// Reference data a test reads: the repository's own copy first (the
// DeepMimic humanoid clips under assets/motions/deepmimic/, MIT), then
// ../shared/data/<relative> next to the repository (or under
// $MIMIC2D_SHARED_DATA when set: CI points it at nothing to prove a fresh
// clone needs no shared folder); empty if neither has it.
inline std::string SharedDataPath(const std::string& relative) {
  const std::string deepmimic = "deepmimic/motions/";
  if (relative.rfind(deepmimic, 0) == 0) {
    const std::string in_repository = SourcePath(
        "assets/motions/deepmimic/" + relative.substr(deepmimic.size()));
    if (std::filesystem::exists(in_repository)) return in_repository;
  }
  const char* shared_override = std::getenv("MIMIC2D_SHARED_DATA");
  const std::string shared =
      shared_override != nullptr
          ? std::string(shared_override)
          : std::string(MIMIC2D_SOURCE_DIR) + "/../shared/data";
  if (shared.empty()) return std::string();
  const std::string path = shared + "/" + relative;
  return std::filesystem::exists(path) ? path : std::string();
}

// Fails the current test (never skips it: a fresh clone must run every
// test) when the data it needs is in neither place.
#define M2D_REQUIRE_SHARED(var, relative)                            \
  const std::string var = ::m2d::testing::SharedDataPath(relative);  \
  if (var.empty()) {                                                 \
    GTEST_FAIL() << "test data " << relative                         \
                 << " is neither under assets/ nor ../shared/data/"; \
  }

// A fresh empty folder under the build's temp area.
inline std::string TempDir(const std::string& name) {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("mimic2d_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_TEST_PATHS_H_
