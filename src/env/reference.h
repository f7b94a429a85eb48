// env: reference bundles prepared for tracking — per view, the 2D points of
// every frame laid out for fast lookup and the image normalization of every
// frame; per bundle, the buffer of initial states.
#ifndef MIMIC2D_ENV_REFERENCE_H_
#define MIMIC2D_ENV_REFERENCE_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "env/observation.h"
#include "env/state_buffer.h"
#include "motion/bundle.h"
#include "sim/simulation.h"

namespace m2d {

// One (bundle, view) pair: what an episode tracks.
struct TrackedView {
  int bundle = 0;
  int view = 0;
  int num_frames = 0;
  int num_points = 0;  // keypoints + object points per frame
  // Frame-major T x num_points: keypoints in layout order, then objects.
  std::vector<Keypoint2D> points;
  // Per frame: the reference's own root and scale (carried over frames
  // where they cannot be measured).
  std::vector<ImageNormalization> normalization;

  const Keypoint2D* frame(int t) const {
    return points.data() + static_cast<size_t>(t) * num_points;
  }
};

// Everything episodes sample from. Immutable after Prepare(), shared by
// every environment.
class TrackingReference {
 public:
  // Checks that every bundle suits `character` (layout, fps = control rate,
  // object names matching the scene's free objects) and lays the views out.
  static std::shared_ptr<const TrackingReference> Prepare(
      std::vector<ReferenceBundle> bundles, const Character& character,
      double control_hz);

  const std::vector<ReferenceBundle>& bundles() const { return bundles_; }
  const std::vector<TrackedView>& views() const { return views_; }
  int num_points() const { return num_points_; }
  int num_object_points() const { return num_object_points_; }
  // Model body id of each object point's free object, in point order.
  const std::vector<int>& object_bodies() const { return object_bodies_; }

 private:
  std::vector<ReferenceBundle> bundles_;
  std::vector<TrackedView> views_;
  int num_points_ = 0;
  int num_object_points_ = 0;
  std::vector<int> object_bodies_;
};

// Initial-state buffers, one per bundle (frames are shared by its views:
// they show the same motion). Mutable by the trainer (ASI), read by envs.
class InitialStates {
 public:
  // Fills each frame from the bundle's 3D ground-truth poses when present
  // (velocities by finite differences), otherwise from the model's default
  // pose placed so that it projects onto the 2D root at the 2D scale.
  // With `joint_noise_rad` > 0 ("Noisy S.I."), every actuated hinge angle of
  // every state gets Gaussian noise of that sigma once, here (kept within
  // the hinge's range), and the character is moved vertically so that its
  // lowest point is where it was without noise, not in the floor.
  InitialStates(const TrackingReference& reference,
                std::shared_ptr<const Character> character,
                const SimulationOptions& simulation_options,
                const StateBufferOptions& options, double joint_noise_rad = 0.0,
                uint64_t noise_seed = 0);

  StateBuffer& buffer(int bundle) { return buffers_[bundle]; }
  const StateBuffer& buffer(int bundle) const { return buffers_[bundle]; }
  int num_bundles() const { return static_cast<int>(buffers_.size()); }

 private:
  std::vector<StateBuffer> buffers_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_REFERENCE_H_
