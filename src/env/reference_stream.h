// env: a 2D reference that arrives frame by frame — a recorded clip played
// out, or a generator (gen/) — and a tracker rollout that follows it as it
// arrives, instead of a reference prepared whole (env/reference.h).
#ifndef MIMIC2D_ENV_REFERENCE_STREAM_H_
#define MIMIC2D_ENV_REFERENCE_STREAM_H_

#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "camera/pinhole.h"
#include "env/policy.h"
#include "env/tracking_env.h"
#include "motion/clip2d.h"
#include "sim/simulation.h"

namespace m2d {

// The source of a streamed reference. Frames come in order; the clip's
// format (layout, fps, image size) is known before the first.
class ReferenceStream {
 public:
  virtual ~ReferenceStream() = default;
  // Layout, fps and image size of the frames; its keypoints are empty.
  virtual const Clip2D& format() const = 0;
  // The next frame's keypoints in layout order into `keypoints`; false when
  // the stream has ended (a generator never ends).
  virtual bool Next(std::vector<Keypoint2D>* keypoints) = 0;
};

// A recorded clip played out frame by frame.
class ClipStream : public ReferenceStream {
 public:
  explicit ClipStream(Clip2D clip);
  const Clip2D& format() const override { return format_; }
  bool Next(std::vector<Keypoint2D>* keypoints) override;

 private:
  Clip2D clip_;
  Clip2D format_;
  int next_frame_ = 0;
};

// The camera that sees frame `frame` when the simulation is at `state` and
// the frame lies `lead_s` seconds ahead of it: a recorded view's camera of
// that frame (state and lead unused), or one that dollies with the
// simulated character (where the character will be at the frame's time).
using StreamCamera = std::function<PinholeCamera(
    int frame, const SimState& state, double lead_s)>;

// One tracker rollout along a stream. Each control step prepares the
// frames it observes (the current one and the L future ones) as a
// one-view reference with their cameras, moves its TrackingEnv onto it
// (Rebase), restarts it from the simulation's current state, and steps it;
// observation, reward and early exit are the environment's own, so a recorded
// clip streamed this way rolls out exactly as the same clip prepared whole
// (tested). The window's cameras are asked for again at every restart, from
// the state the step starts at: the step projects the character with the
// next frame's camera, asked one control period ahead. (Asked once, when a
// frame entered the window, a camera following the character lagged it by
// L frames: at walking speed 20 cm, a 20-45 px offset the tracker chased
// until it fell.) Object tracks are not streamed.
class StreamedRollout {
 public:
  // `options.max_episode_s` and `options.early_exit` apply as in training;
  // `start` is the state of the stream's first frame.
  StreamedRollout(std::shared_ptr<const Character> character,
                  const TrackingEnvOptions& options, ReferenceStream* stream,
                  StreamCamera camera, const SimState& start);

  // Advances one control period with `policy`; false once the rollout has
  // ended (the stream ran out, the episode's time limit, an early exit or
  // a divergence), after which it does nothing.
  bool Step(Policy& policy);

  int frame() const { return frame_; }  // the stream frame tracked now
  // The rollout's counts over the whole stream (view_index and
  // start_frame 0).
  const EpisodeStats& stats() const { return stats_; }
  // The last step's error against the frame it reached, and whether that
  // step diverged (for per-frame records: where a stream starts to fail).
  const ReprojectionError& last_error() const { return last_error_; }
  bool diverged() const { return diverged_; }
  const Simulation& simulation() const { return env_->simulation(); }
  // The current frame's reference keypoints and camera, for drawing.
  const std::vector<Keypoint2D>& reference_frame() const;
  const PinholeCamera& camera() const { return cameras_.front(); }

 private:
  // Reads frames until the window [frame_, frame_ + L] is full or the
  // stream ends; false when not even frame_ + 1 exists.
  bool FillWindow();
  // Each window frame's camera, asked at `state`.
  void AskCameras(const SimState& state);
  // The TrackingEnv on the window, started from `state`.
  void Restart(const SimState& state);

  std::shared_ptr<const Character> character_;
  TrackingEnvOptions options_;
  ReferenceStream* stream_;
  StreamCamera camera_;
  std::unique_ptr<TrackingEnv> env_;
  // Frames frame_ .. frame_ + window_.size() - 1, and their cameras.
  std::deque<std::vector<Keypoint2D>> window_;
  std::deque<PinholeCamera> cameras_;
  bool stream_ended_ = false;
  bool ended_ = false;
  bool diverged_ = false;
  int frame_ = 0;
  EpisodeStats stats_;
  ReprojectionError last_error_;
  std::vector<float> observation_, action_;
  SimState state_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_REFERENCE_STREAM_H_
