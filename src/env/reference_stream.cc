#include "env/reference_stream.h"

#include <utility>

#include "common/error.h"
#include "env/reference.h"
#include "motion/bundle.h"

namespace m2d {

ClipStream::ClipStream(Clip2D clip) : clip_(std::move(clip)) {
  format_.layout = clip_.layout;
  format_.fps = clip_.fps;
  format_.image_width_px = clip_.image_width_px;
  format_.image_height_px = clip_.image_height_px;
}

bool ClipStream::Next(std::vector<Keypoint2D>* keypoints) {
  if (next_frame_ >= clip_.num_frames()) return false;
  const Keypoint2D* frame = clip_.keypoints.frame(next_frame_++);
  keypoints->assign(frame, frame + clip_.keypoints.num_keypoints());
  return true;
}

StreamedRollout::StreamedRollout(std::shared_ptr<const Character> character,
                                 const TrackingEnvOptions& options,
                                 ReferenceStream* stream, StreamCamera camera,
                                 const SimState& start)
    : character_(std::move(character)),
      options_(options),
      stream_(stream),
      camera_(std::move(camera)),
      state_(start) {
  options_.Validate();
  if (options_.target != TrackingTarget::kImage2D)
    throw ConfigError("a streamed reference is 2D: env.target image_2d");
  // The stream's cameras are asked of `camera` each step, following the
  // character already when it dollies; the env projects with them as given.
  options_.camera = EpisodeCamera::kRecorded;
  const Clip2D& format = stream_->format();
  if (format.layout != &character_->keypoint_layout()) {
    throw InputError("reference stream",
                     "layout " + format.layout->name +
                         " differs from the character's " +
                         character_->keypoint_layout().name);
  }
  if (!FillWindow()) {
    throw InputError("reference stream", "needs at least 2 frames");
  }
  Restart(state_);
}

bool StreamedRollout::FillWindow() {
  // Outline: frames enter at the back until the current frame and its L
  // future frames are in.
  const size_t wanted = options_.num_future_frames + 1;
  std::vector<Keypoint2D> keypoints;
  while (window_.size() < wanted && !stream_ended_) {
    if (!stream_->Next(&keypoints)) {
      stream_ended_ = true;
      break;
    }
    if (static_cast<int>(keypoints.size()) !=
        character_->keypoint_layout().num_keypoints()) {
      throw InputError(
          "reference stream",
          "frame " + std::to_string(frame_ + window_.size()) + " has " +
              std::to_string(keypoints.size()) + " keypoints, the layout " +
              std::to_string(character_->keypoint_layout().num_keypoints()));
    }
    window_.push_back(keypoints);
  }
  return window_.size() >= 2;
}

void StreamedRollout::AskCameras(const SimState& state) {
  const double dt_s = 1.0 / options_.simulation.control_hz;
  cameras_.clear();
  for (size_t t = 0; t < window_.size(); ++t) {
    cameras_.push_back(camera_(frame_ + static_cast<int>(t), state, t * dt_s));
  }
}

void StreamedRollout::Restart(const SimState& state) {
  // Outline: the window as a one-view bundle with per-frame cameras (asked
  // at `state`), prepared as any reference is (cameras: truth, the bundle's
  // own), then the TrackingEnv moved onto it (made once), reset to the
  // window's first frame at `state`.
  AskCameras(state);
  const Clip2D& format = stream_->format();
  ReferenceBundle bundle;
  bundle.name = "stream";
  bundle.fps = format.fps;
  ReferenceView view;
  view.name = "stream";
  view.clip.layout = format.layout;
  view.clip.fps = format.fps;
  view.clip.image_width_px = format.image_width_px;
  view.clip.image_height_px = format.image_height_px;
  const int num_keypoints = format.layout->num_keypoints();
  view.clip.keypoints =
      KeypointTrack(static_cast<int>(window_.size()), num_keypoints);
  for (size_t t = 0; t < window_.size(); ++t) {
    for (int j = 0; j < num_keypoints; ++j)
      view.clip.keypoints.at(static_cast<int>(t), j) = window_[t][j];
  }
  view.cameras.assign(cameras_.begin(), cameras_.end());
  bundle.views.push_back(std::move(view));
  TaskSources sources;
  sources.initial_states = InitialStateSource::kDefault;
  sources.cameras = CameraSource::kTruth;
  auto reference =
      TrackingReference::Prepare({std::move(bundle)}, *character_,
                                 options_.simulation.control_hz, sources);
  if (env_ == nullptr) {
    env_ = std::make_unique<TrackingEnv>(character_, std::move(reference),
                                         nullptr, options_, 0);
    observation_.resize(env_->observation_size());
    action_.resize(env_->action_size());
  } else {
    env_->Rebase(std::move(reference));
  }
  env_->ResetTo(0, 0, state, observation_.data());
}

bool StreamedRollout::Step(Policy& policy) {
  // Outline: act on the window's observation, step, count; then slide the
  // window one frame and restart on it unless the rollout ended.
  if (ended_) return false;
  policy.Act(observation_.data(), 1, action_.data());
  const StepOutcome outcome = env_->Step(action_.data(), observation_.data());
  ++stats_.steps;
  stats_.total_reward += outcome.reward;
  if (outcome.error.num_present > 0) {
    ++stats_.measured_steps;
    stats_.sum_mean_error_px += outcome.error.mean_px;
  }
  stats_.max_error_px = std::max(stats_.max_error_px, outcome.error.max_px);
  last_error_ = outcome.error;
  diverged_ = outcome.diverged;
  ++frame_;
  window_.pop_front();
  cameras_.pop_front();
  if (outcome.terminated) {
    stats_.failed = true;
    ended_ = true;
    return false;
  }
  state_ = env_->simulation().Save();
  if (stats_.steps >= options_.max_episode_steps() || !FillWindow()) {
    ended_ = true;
    return false;
  }
  Restart(state_);
  return true;
}

const std::vector<Keypoint2D>& StreamedRollout::reference_frame() const {
  return window_.front();
}

}  // namespace m2d
