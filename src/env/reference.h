// env: reference bundles prepared for tracking — per view, the 2D points of
// every frame laid out for fast lookup and the image normalization of every
// frame; the buffers of initial states (per bundle, or per view when they
// come from a per-view estimate).
#ifndef MIMIC2D_ENV_REFERENCE_H_
#define MIMIC2D_ENV_REFERENCE_H_

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "env/observation.h"
#include "env/reward.h"
#include "env/sources.h"
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
  // object names matching the scene's free objects) and the `sources`, and
  // lays the views out. Keeps a sanitized copy of each bundle, so nothing
  // downstream can read what the sources exclude:
  //  - ground_truth only with initial_states: truth;
  //  - with cameras: estimate, each view's cameras are its estimate's;
  //  - the estimate only with initial_states: estimate.
  // InputError naming the bundle when a source is missing from it.
  static std::shared_ptr<const TrackingReference> Prepare(
      std::vector<ReferenceBundle> bundles, const Character& character,
      double control_hz, const TaskSources& sources = TaskSources());

  const TaskSources& sources() const { return sources_; }
  const std::vector<ReferenceBundle>& bundles() const { return bundles_; }
  const std::vector<TrackedView>& views() const { return views_; }
  int num_points() const { return num_points_; }
  int num_object_points() const { return num_object_points_; }
  // Model body id of each object point's free object, in point order.
  const std::vector<int>& object_bodies() const { return object_bodies_; }

 private:
  TaskSources sources_;
  std::vector<ReferenceBundle> bundles_;
  std::vector<TrackedView> views_;
  int num_points_ = 0;
  int num_object_points_ = 0;
  std::vector<int> object_bodies_;
};

// A hash of every tracked view's 2D keypoints (coordinates and
// confidences) and frame counts: two references with equal frame counts but
// different motion differ. Reads the 2D only.
uint64_t ReferenceFingerprint(const TrackingReference& reference);

// The simulation's current state as 3D tracking compares it, with
// `keypoints_xyz` its KeypointPositions (reuses `target`'s vectors).
void ReadBodyTarget(const Simulation& simulation, const double* keypoints_xyz,
                    BodyTarget3D* target);

// The `estimate` initial state of `frame` of a view's fitted `poses`: that
// pose, moving at the poses' central differences, lifted out of the floor
// when it grazes it. What InitialStates fills from an estimate, and what a
// generated stream's rollout starts from (its first seconds fitted).
// ConfigError for a frame outside the poses.
SimState EstimatedState(std::shared_ptr<const Character> character,
                        const SimulationOptions& simulation_options,
                        const std::vector<Pose3D>& poses, int frame);

// The `default` initial state of a frame seen by `camera` whose image root
// and scale are `image`: the model's default pose, turned to face the
// camera and moved so that its root keypoints project onto the 2D root, at
// the height they have standing; at rest.
SimState PlacedDefaultState(std::shared_ptr<const Character> character,
                            const SimulationOptions& simulation_options,
                            const PinholeCamera& camera,
                            const ImageNormalization& image);

// Initial-state buffers. From the truth or the default pose, one per bundle
// (frames are shared by its views: they show the same motion, in one world
// frame); from an estimate, one per view (each view's poses are in its own
// world frame). Mutable by the trainer (ASI), read by envs.
class InitialStates {
 public:
  // Fills each frame as the reference's sources say:
  //  - truth: the bundle's 3D ground-truth poses (velocities by central
  //    differences);
  //  - estimate: the view's estimated poses (velocities likewise), lifted
  //    when the character's lowest point is below the floor;
  //  - default: the model's default pose placed so that it projects onto
  //    the 2D root at the 2D scale (from the bundle's first view).
  // With `joint_noise_rad` > 0 ("Noisy S.I."), every actuated hinge angle of
  // every state gets Gaussian noise of that sigma once, here (kept within
  // the hinge's range), and the character is moved vertically so that its
  // lowest point is where it was without noise, not in the floor.
  InitialStates(const TrackingReference& reference,
                std::shared_ptr<const Character> character,
                const SimulationOptions& simulation_options,
                const StateBufferOptions& options, double joint_noise_rad = 0.0,
                uint64_t noise_seed = 0);

  StateBuffer& buffer(int index) { return buffers_[index]; }
  const StateBuffer& buffer(int index) const { return buffers_[index]; }
  int num_buffers() const { return static_cast<int>(buffers_.size()); }
  // The buffer episodes on `view_index` (into TrackingReference::views())
  // start from.
  int BufferOf(int view_index) const { return buffer_of_view_[view_index]; }
  StateBuffer& BufferOfView(int view_index) {
    return buffers_[BufferOf(view_index)];
  }
  const StateBuffer& BufferOfView(int view_index) const {
    return buffers_[BufferOf(view_index)];
  }
  // The motion buffer `index` was filled from, per frame, before any noise:
  // the truth's or a view's fitted poses (or the placed default pose), as
  // the character holds them. The 3D-tracking baselines' reference.
  const std::vector<BodyTarget3D>& motion(int index) const {
    return motions_[index];
  }
  // Which view an episode starts on (TrackingEnv::Reset): uniformly until
  // weights are set, then in proportion to them (hard-view sampling,
  // rl/hard_views.h). Set between rollouts, as the buffers are.
  // ConfigError unless one finite weight >= 0 per view, not all zero.
  void SetViewWeights(const std::vector<double>& weights);
  int DrawView(std::mt19937_64& rng) const;
  int num_views() const { return static_cast<int>(buffer_of_view_.size()); }
  // ReferenceFingerprint of the reference the buffers were filled for: a
  // checkpoint's buffers are restored only into the same reference.
  uint64_t reference_fingerprint() const { return reference_fingerprint_; }

 private:
  uint64_t reference_fingerprint_ = 0;
  std::vector<StateBuffer> buffers_;
  std::vector<std::vector<BodyTarget3D>> motions_;
  std::vector<int> buffer_of_view_;
  // Running sums of the view weights; empty: uniform.
  std::vector<double> view_cumulative_weights_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_REFERENCE_H_
