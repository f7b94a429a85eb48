// tests/gen: the repository's DeepMimic clips as generator data.
#ifndef MIMIC2D_TESTS_GEN_GEN_TEST_DATA_H_
#define MIMIC2D_TESTS_GEN_GEN_TEST_DATA_H_

#include <memory>
#include <string>
#include <vector>

#include "gen/motion_dataset.h"
#include "motion/motion_io.h"
#include "test_paths.h"

namespace m2d::testing {

// assets/motions/deepmimic/humanoid3d_<clip>.txt at 30 Hz with its COCO-17 map.
inline GenMotionSource DeepMimicSource(const std::string& clip) {
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(SourcePath("assets/skeletons/humanoid.yaml")));
  return {
      clip,
      ReadDeepMimicMotion(
          SourcePath("assets/motions/deepmimic/humanoid3d_" + clip + ".txt"),
          skeleton, 30.0),
      LoadKeypointMap(SourcePath("assets/skeletons/humanoid.coco17.yaml"),
                      *skeleton)};
}

// The clip seen from `azimuths` x `elevations_deg`, looping cycles to
// `loop_to_s`.
inline GenDataset ClipDataset(const std::string& clip, int azimuths,
                              std::vector<double> elevations_deg,
                              double loop_to_s) {
  GenViewOptions views;
  views.num_azimuths = azimuths;
  views.elevations_deg = std::move(elevations_deg);
  return BuildGenDataset({DeepMimicSource(clip)}, views, 30.0, loop_to_s);
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_GEN_GEN_TEST_DATA_H_
