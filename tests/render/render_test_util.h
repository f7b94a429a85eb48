// tests: helpers for the render tests — the humanoid and a centroid (image
// comparisons, PNG headers and ffprobe: tests/media/media_test_util.h).
#ifndef MIMIC2D_TESTS_RENDER_RENDER_TEST_UTIL_H_
#define MIMIC2D_TESTS_RENDER_RENDER_TEST_UTIL_H_

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "media/media_test_util.h"
#include "sim/simulation.h"
#include "test_paths.h"

namespace m2d::testing {

inline std::shared_ptr<const Character> LoadRenderHumanoid() {
  return LoadCharacterForSimulation(
      SourcePath("assets/characters/humanoid.yaml"), "flat",
      SimulationOptions());
}

// Mean of a set of points (the look-at target of the test cameras).
inline Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : points) sum += point;
  return sum / static_cast<double>(points.size());
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_RENDER_RENDER_TEST_UTIL_H_
