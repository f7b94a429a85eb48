// cli: shared options for reading a 3D motion and making a bundle from it.
#ifndef MIMIC2D_CLI_MOTION_SOURCE_H_
#define MIMIC2D_CLI_MOTION_SOURCE_H_

#include <CLI/CLI.hpp>
#include <string>

#include "motion/bundle.h"
#include "motion/motion3d.h"
#include "motion/skeleton.h"

namespace m2d::cli {

struct MotionSourceArgs {
  std::string path;               // .txt (DeepMimic) or .bvh
  std::string character;          // DeepMimic: config naming both below
  std::string skeleton;           // DeepMimic: skeleton YAML
  std::string keypoint_map;       // keypoint map YAML
  double bvh_scale_m = 0.056444;  // metres per BVH unit (CMU/cgspeed)
  double fps = 0.0;               // resampled to this rate; <= 0: the file's
};

struct LoadedMotion {
  Motion3D motion;
  KeypointMap keypoint_map;
};

void AddMotionSourceOptions(CLI::App& command, MotionSourceArgs* args);
void AddBundleOptions(CLI::App& command, BundleFromMotionOptions* options,
                      bool* follow);
LoadedMotion LoadMotionSource(const MotionSourceArgs& args);
void PrintBundleSummary(const ReferenceBundle& bundle, const std::string& path);
// The bundle at `truth_path` holding `bundle`'s 3D truth and true cameras
// (e.g. the original of a stripped bundle), for measuring a fit against it.
// InputError naming the file when it has no truth or its views or frames
// differ from `bundle`'s (read from `bundle_path`).
ReferenceBundle ReadMatchingTruth(const std::string& truth_path,
                                  const ReferenceBundle& bundle,
                                  const std::string& bundle_path);

}  // namespace m2d::cli

#endif  // MIMIC2D_CLI_MOTION_SOURCE_H_
