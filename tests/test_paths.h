// tests: where the project's assets and the shared reference data live.
#ifndef MIMIC2D_TESTS_TEST_PATHS_H_
#define MIMIC2D_TESTS_TEST_PATHS_H_

#include <unistd.h>

#include <filesystem>
#include <string>

namespace m2d::testing {

inline std::string SourcePath(const std::string& relative) {
  return std::string(MIMIC2D_SOURCE_DIR) + "/" + relative;
}

// ../shared/data/<relative> next to the repository; empty if absent.
inline std::string SharedDataPath(const std::string& relative) {
  std::string path =
      std::string(MIMIC2D_SOURCE_DIR) + "/../shared/data/" + relative;
  return std::filesystem::exists(path) ? path : std::string();
}

// Skips the current test with a clear message when shared data is absent.
#define M2D_REQUIRE_SHARED(var, relative)                           \
  const std::string var = ::m2d::testing::SharedDataPath(relative); \
  if (var.empty()) {                                                \
    GTEST_SKIP() << "shared data ../shared/data/" << relative       \
                 << " is absent; skipping";                         \
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
