#include "env/tracking_env.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "common/error.h"

namespace m2d {

void PushOptions::Validate() const {
  CheckRanges(*this, "pushes");
  if (duration_s > every_s) {
    throw ConfigError("pushes: duration_s (" + std::to_string(duration_s) +
                      " s) must be at most every_s (" +
                      std::to_string(every_s) + " s)");
  }
}

int PushAtStep(int step, double control_hz, const PushOptions& pushes) {
  if (pushes.force_n <= 0) return 0;
  // A step is placed at its middle, so that 2 s at 30 Hz is step 60
  // whatever the rounding.
  const double time_s = (step + 0.5) / control_hz;
  const int k = static_cast<int>(std::floor(time_s / pushes.every_s));
  if (k < 1) return 0;
  return time_s - k * pushes.every_s < pushes.duration_s ? k : 0;
}

namespace {

// Moves each tracked object (`object_bodies`) of `state` on the floor by an
// offset drawn uniformly in a square of side `square_m` about where it was
// (x and y, two draws per object, in free_objects() order).
void OffsetObjectStarts(const Character& character,
                        const std::vector<int>& object_bodies, double square_m,
                        std::mt19937_64& rng, SimState* state) {
  std::uniform_real_distribution<double> offset_m(-0.5 * square_m,
                                                  0.5 * square_m);
  for (const FreeObject& object : character.free_objects()) {
    if (std::find(object_bodies.begin(), object_bodies.end(), object.body_id) ==
        object_bodies.end())
      continue;
    state->qpos[object.qpos_address] += offset_m(rng);
    state->qpos[object.qpos_address + 1] += offset_m(rng);
  }
}

}  // namespace

void TrackingEnvOptions::Validate() const {
  CheckRanges(*this, "env");
  pushes.Validate();
}

TrackingEnv::TrackingEnv(std::shared_ptr<const Character> character,
                         std::shared_ptr<const TrackingReference> reference,
                         std::shared_ptr<const InitialStates> initial_states,
                         const TrackingEnvOptions& options, uint64_t seed,
                         int num_observed_views)
    : reference_(std::move(reference)),
      initial_states_(std::move(initial_states)),
      options_(options),
      simulation_(character, options.simulation),
      rng_(seed),
      num_observed_views_(num_observed_views) {
  options_.Validate();
  if (num_observed_views < 1 || num_observed_views > kMaxObservedViews) {
    throw ConfigError("env: num_observed_views must be in [1, " +
                      std::to_string(kMaxObservedViews) + "], got " +
                      std::to_string(num_observed_views));
  }
  observed_views_.resize(num_observed_views, nullptr);
  clean_views_.resize(num_observed_views, nullptr);
  noisy_views_.resize(num_observed_views);
  if (options_.target == TrackingTarget::kBody3D) {
    // The 3D baselines follow the initial states' motion, alone.
    if (num_observed_views != 1)
      throw ConfigError("env: target body_3d observes one view");
    if (reference_->sources().initial_states == InitialStateSource::kDefault) {
      throw ConfigError(
          "env: target body_3d needs a 3D reference: initial_states truth "
          "or estimate, not default");
    }
  }
  if (options_.camera != EpisodeCamera::kRecorded &&
      (initial_states_ == nullptr ||
       reference_->sources().initial_states == InitialStateSource::kDefault)) {
    // The camera follows the character relative to a motion's root.
    throw ConfigError(std::string("env: camera ") +
                      SettingName(options_.camera) +
                      " needs the motion the initial states come from: "
                      "initial_states truth or estimate, not default");
  }
  if (options_.object_start_square_m > 0 &&
      reference_->num_object_points() == 0) {
    throw ConfigError(
        "env: object_start_square_m moves tracked objects (a ball); these "
        "bundles track none");
  }
  layout_.num_bodies = static_cast<int>(character->bodies().size());
  layout_.num_objects = reference_->num_object_points();
  layout_.num_points = reference_->num_points();
  layout_.num_future_frames = options_.num_future_frames;
  if (options_.critic_observes_3d) {
    layout_.critic_only_size =
        CriticOnlySize(character->keypoint_layout().num_keypoints());
  }

  const int num_points = reference_->num_points();
  const int num_keypoints = character->keypoint_layout().num_keypoints();
  keypoints_xyz_.resize(3 * num_keypoints);
  current_points_m_.resize(num_points);
  cameras_.resize(num_observed_views);
  projected_xy_.resize(2 * num_points * num_observed_views);
  in_front_.reset(new bool[num_points * num_observed_views]);
  projected_points_.resize(num_points * num_observed_views);
  const size_t num_bodies = character->bodies().size();
  bodies_.positions_m.resize(num_bodies);
  bodies_.orientations.resize(num_bodies);
  bodies_.linear_velocities_m_s.resize(num_bodies);
  bodies_.angular_velocities_rad_s.resize(num_bodies);
  object_positions_.resize(layout_.num_objects);
  object_velocities_.resize(layout_.num_objects);
}

void TrackingEnv::Rebase(std::shared_ptr<const TrackingReference> reference) {
  if (reference->num_points() != reference_->num_points() ||
      reference->object_bodies() != reference_->object_bodies()) {
    throw ConfigError(
        "env: a new reference must keep the points and objects tracked");
  }
  reference_ = std::move(reference);
  std::fill(observed_views_.begin(), observed_views_.end(), nullptr);
  view_ = nullptr;
  episode_corrupted_ = false;
}

void TrackingEnv::SetReferenceNoise(const ReferenceNoise& noise) {
  reference_noise_ = noise;
}

void TrackingEnv::Reset(float* observation) {
  // Outline: pick a view (uniformly, or as hard-view sampling weighs them),
  // a start frame (the first with first_frame_start_share, else uniformly,
  // leaving at least one step), an initial state from that frame's buffer.
  const int view_index = initial_states_->DrawView(rng_);
  const TrackedView& view = reference_->views()[view_index];
  const bool start_at_first_frame =
      options_.first_frame_start_share > 0.0 &&
      std::uniform_real_distribution<double>(0.0, 1.0)(rng_) <
          options_.first_frame_start_share;
  int frame = 0;
  if (!start_at_first_frame) {
    frame = std::uniform_int_distribution<int>(0, view.num_frames - 2)(rng_);
  }
  const StateBuffer& buffer = initial_states_->BufferOfView(view_index);
  ResetTo(view_index, frame, buffer.Draw(frame, rng_), observation);
}

void TrackingEnv::ResetTo(int view_index, int frame, const SimState& state,
                          float* observation) {
  if (num_observed_views_ != 1) {
    throw ConfigError("env: an environment observing " +
                      std::to_string(num_observed_views_) +
                      " views starts with ResetToViews");
  }
  RestoreStart(state);
  observed_views_[0] = &reference_->views()[view_index];
  episode_.view_index = view_index;
  BeginEpisode(frame);
  ProjectCurrentPoints();
  WriteObservation(observation);
}

void TrackingEnv::ResetToViews(const std::vector<int>& view_indices, int frame,
                               const SimState& state, float* observation) {
  // Outline: check that the views are K views of one bundle, then start as
  // ResetTo does.
  if (static_cast<int>(view_indices.size()) != num_observed_views_) {
    throw ConfigError("env: " + std::to_string(view_indices.size()) +
                      " views given to an environment observing " +
                      std::to_string(num_observed_views_));
  }
  const std::vector<TrackedView>& views = reference_->views();
  for (size_t k = 0; k < view_indices.size(); ++k) {
    const int index = view_indices[k];
    if (index < 0 || index >= static_cast<int>(views.size()) ||
        views[index].bundle != views[view_indices[0]].bundle) {
      throw ConfigError(
          "env: the observed views must be views of one bundle (view index " +
          std::to_string(index) + ")");
    }
    observed_views_[k] = &views[index];
  }
  RestoreStart(state);
  episode_.view_index = view_indices[0];
  BeginEpisode(frame);
  ProjectCurrentPoints();
  WriteObservation(observation);
}

void TrackingEnv::RestoreStart(const SimState& state) {
  if (options_.object_start_square_m <= 0) {
    simulation_.Restore(state);
    return;
  }
  moved_start_ = state;
  OffsetObjectStarts(simulation_.character(), reference_->object_bodies(),
                     options_.object_start_square_m, rng_, &moved_start_);
  simulation_.Restore(moved_start_);
}

void TrackingEnv::BeginEpisode(int frame) {
  view_ = observed_views_[0];
  frame_ = frame;
  const int view_index = episode_.view_index;
  episode_ = EpisodeStats();
  episode_.view_index = view_index;
  episode_.start_frame = frame;
  // A state captured mid-push (ASI) carries its force: no episode starts
  // pushed.
  push_ = 0;
  if (options_.pushes.force_n > 0) SetRootPush(0.0, 0.0);
  episode_corrupted_ = reference_noise_.enabled();
  if (episode_corrupted_) {
    // The episode observes corrupted copies of its views, drawn from here
    // on as it reaches their frames.
    for (int k = 0; k < num_observed_views_; ++k) {
      const TrackedView& clean = *observed_views_[k];
      TrackedView& noisy = noisy_views_[k];
      noisy.bundle = clean.bundle;
      noisy.view = clean.view;
      noisy.num_frames = clean.num_frames;
      noisy.num_points = clean.num_points;
      noisy.points.resize(clean.points.size());
      noisy.normalization = clean.normalization;
      clean_views_[k] = &clean;
      observed_views_[k] = &noisy;
    }
    view_ = observed_views_[0];
    corrupted_until_frame_ = frame - 1;
    CorruptReferenceUpTo(frame + options_.num_future_frames);
  }
}

void TrackingEnv::CorruptReferenceUpTo(int last_frame) {
  last_frame = std::min(last_frame, view_->num_frames - 1);
  for (int t = corrupted_until_frame_ + 1; t <= last_frame; ++t) {
    for (int k = 0; k < num_observed_views_; ++k) {
      const Keypoint2D* clean = clean_views_[k]->frame(t);
      Keypoint2D* noisy = noisy_views_[k].points.data() +
                          static_cast<size_t>(t) * noisy_views_[k].num_points;
      for (int j = 0; j < noisy_views_[k].num_points; ++j) {
        noisy[j] = clean[j];
        if (!noisy[j].IsPresent()) continue;  // a miss stays a miss
        CorruptKeypoint(reference_noise_.pixel_sigma_px,
                        reference_noise_.drop_probability, rng_, unit_normal_,
                        unit_uniform_, &noisy[j]);
      }
    }
  }
  corrupted_until_frame_ = std::max(corrupted_until_frame_, last_frame);
}

StepOutcome TrackingEnv::Step(const float* action, float* observation) {
  // Outline: physics, advance the reference, measure the reprojection,
  // reward, decide whether the episode ends, observe.
  StepOutcome outcome;
  if (options_.pushes.force_n > 0) {
    const int push = PushAtStep(episode_.steps, options_.simulation.control_hz,
                                options_.pushes);
    if (push != push_) {
      push_ = push;
      SetRootPush(
          push > 0 ? options_.pushes.force_n : 0.0,
          push > 0 ? std::uniform_real_distribution<double>(0, 2 * M_PI)(rng_)
                   : 0.0);
    }
  }
  StepResult physics = simulation_.Step(action);
  ++frame_;
  ++episode_.steps;
  if (physics.diverged()) {
    outcome.terminated = outcome.diverged = true;
    episode_.failed = true;
    return outcome;
  }
  if (episode_corrupted_)
    CorruptReferenceUpTo(frame_ + options_.num_future_frames);
  ProjectCurrentPoints();
  const int num_keypoints =
      simulation_.character().keypoint_layout().num_keypoints();
  const int num_points = layout_.num_points;
  // Per observed view (one in training): keypoint and object errors; the
  // reward of the views' combined errors.
  ReprojectionError pose_errors[kMaxObservedViews];
  ReprojectionError object_errors[kMaxObservedViews];
  for (int k = 0; k < num_observed_views_; ++k) {
    const Keypoint2D* target = observed_views_[k]->frame(frame_);
    const double* projected = projected_xy_.data() + 2 * k * num_points;
    const bool* in_front = in_front_.get() + k * num_points;
    pose_errors[k] =
        MeasureReprojection(projected, in_front, target, num_keypoints);
    if (layout_.num_objects > 0) {
      object_errors[k] = MeasureReprojection(
          projected + 2 * num_keypoints, in_front + num_keypoints,
          target + num_keypoints, layout_.num_objects);
    }
  }
  outcome.error = CombineViewErrors(pose_errors, num_observed_views_);
  ReprojectionError object_error =
      CombineViewErrors(object_errors, num_observed_views_);
  bool off_3d_reference = false;
  if (options_.target == TrackingTarget::kImage2D) {
    outcome.terms = ComputeReward(
        outcome.error, physics.mean_abs_power_w,
        layout_.num_objects > 0 ? &object_error : nullptr, options_.reward);
  } else {
    ReadBodyTarget(simulation_, keypoints_xyz_.data(), &simulated_body_);
    ReadObjectKinematics();
    simulated_body_.object_positions_m = object_positions_;
    const Tracking3DError error_3d =
        MeasureTracking3D(simulated_body_, ReferenceBody(frame_));
    outcome.terms =
        ComputeReward3D(error_3d, physics.mean_abs_power_w, options_.reward_3d,
                        options_.reward.energy_weight);
    off_3d_reference =
        options_.reward_3d.early_exit_max_error_m > 0 &&
        error_3d.max_keypoint_m > options_.reward_3d.early_exit_max_error_m;
  }
  outcome.reward = static_cast<float>(outcome.terms.total);

  episode_.total_reward += outcome.terms.total;
  if (outcome.error.num_present > 0) {
    ++episode_.measured_steps;
    episode_.sum_mean_error_px += outcome.error.mean_px;
  }
  episode_.max_error_px = std::max(episode_.max_error_px, outcome.error.max_px);

  if (off_3d_reference ||
      (options_.early_exit &&
       ShouldExitEarly(outcome.error, options_.early_exit_max_error_px,
                       options_.early_exit_measure))) {
    outcome.terminated = true;
    episode_.failed = true;
    return outcome;
  }
  outcome.reference_ended = frame_ >= view_->num_frames - 1;
  outcome.truncated =
      outcome.reference_ended || episode_.steps >= options_.max_episode_steps();
  WriteObservation(observation);
  return outcome;
}

PinholeCamera CameraFollowingCharacter(
    const PinholeCamera& recorded, const Eigen::Vector3d& reference_root_m,
    const Eigen::Vector3d& simulated_root_m) {
  const Eigen::Vector3d offset_m = simulated_root_m - reference_root_m;
  return recorded.Translated({offset_m.x(), offset_m.y(), 0.0});
}

void TrackingEnv::PlaceCameras() {
  // The frame whose camera (and reference root) the episode's camera is
  // placed from: the current one, or the start's for a rigid dolly.
  const int camera_frame = options_.camera == EpisodeCamera::kDolliesFromStart
                               ? episode_.start_frame
                               : frame_;
  for (int k = 0; k < num_observed_views_; ++k) {
    const TrackedView& view = *observed_views_[k];
    cameras_[k] = reference_->bundles()[view.bundle].views[view.view].CameraAt(
        camera_frame);
  }
  if (options_.camera == EpisodeCamera::kRecorded) return;
  // One offset for every view: the observed views of an episode share the
  // episode view's world (ResetToViews), where the simulation is.
  const double* root_qpos =
      simulation_.data()->qpos + simulation_.character().root_qpos_address();
  const Eigen::Vector3d simulated_root_m(root_qpos[0], root_qpos[1],
                                         root_qpos[2]);
  const Eigen::Vector3d& reference_root_m =
      ReferenceBody(camera_frame).root_position_m;
  for (PinholeCamera& camera : cameras_) {
    camera =
        CameraFollowingCharacter(camera, reference_root_m, simulated_root_m);
  }
}

void TrackingEnv::ProjectCurrentPoints() {
  // Outline: the keypoints (and objects) in the world once, then through
  // each observed view's camera at the current frame.
  PlaceCameras();
  const mjData* data = simulation_.data();
  simulation_.KeypointPositions(keypoints_xyz_.data());
  const int num_keypoints = static_cast<int>(keypoints_xyz_.size() / 3);
  const int num_points = layout_.num_points;
  for (int k = 0; k < num_observed_views_; ++k) {
    const PinholeCamera& camera = cameras_[k];
    for (int j = 0; j < num_points; ++j) {
      Eigen::Vector3d point;
      if (j < num_keypoints) {
        point = {keypoints_xyz_[3 * j], keypoints_xyz_[3 * j + 1],
                 keypoints_xyz_[3 * j + 2]};
      } else {
        const double* xpos =
            data->xpos + 3 * reference_->object_bodies()[j - num_keypoints];
        point = {xpos[0], xpos[1], xpos[2]};
      }
      Projection projection = camera.Project(point);
      const int slot = k * num_points + j;
      projected_xy_[2 * slot] = projection.pixel_px.x();
      projected_xy_[2 * slot + 1] = projection.pixel_px.y();
      in_front_[slot] = projection.in_front;
      projected_points_[slot] = {projection.pixel_px.x(),
                                 projection.pixel_px.y(),
                                 projection.in_front ? 1.0 : 0.0};
    }
  }
}

const BodyTarget3D& TrackingEnv::ReferenceBody(int frame) const {
  const std::vector<BodyTarget3D>& motion =
      initial_states_->motion(initial_states_->BufferOf(episode_.view_index));
  return motion[std::min(frame, static_cast<int>(motion.size()) - 1)];
}

void TrackingEnv::SetRootPush(double force_n, double heading_rad) {
  const int root = simulation_.character().bodies()[0];
  double* wrench = simulation_.mutable_data()->xfrc_applied + 6 * root;
  wrench[0] = force_n * std::cos(heading_rad);
  wrench[1] = force_n * std::sin(heading_rad);
  wrench[2] = 0.0;
}

void TrackingEnv::ReadBodyKinematics() {
  const mjModel* model = simulation_.model();
  const mjData* data = simulation_.data();
  const std::vector<int>& body_ids = simulation_.character().bodies();
  mjtNum velocity[6];  // angular, then linear (world frame)
  for (size_t b = 0; b < body_ids.size(); ++b) {
    const int id = body_ids[b];
    bodies_.positions_m[b] = {data->xpos[3 * id], data->xpos[3 * id + 1],
                              data->xpos[3 * id + 2]};
    bodies_.orientations[b] =
        Eigen::Quaterniond(data->xquat[4 * id], data->xquat[4 * id + 1],
                           data->xquat[4 * id + 2], data->xquat[4 * id + 3]);
    mj_objectVelocity(model, data, mjOBJ_BODY, id, velocity, 0);
    bodies_.angular_velocities_rad_s[b] = {velocity[0], velocity[1],
                                           velocity[2]};
    bodies_.linear_velocities_m_s[b] = {velocity[3], velocity[4], velocity[5]};
  }
  ReadObjectKinematics();
}

void TrackingEnv::ReadObjectKinematics() {
  const mjModel* model = simulation_.model();
  const mjData* data = simulation_.data();
  mjtNum velocity[6];  // angular, then linear (world frame)
  for (int o = 0; o < layout_.num_objects; ++o) {
    const int id = reference_->object_bodies()[o];
    object_positions_[o] = {data->xpos[3 * id], data->xpos[3 * id + 1],
                            data->xpos[3 * id + 2]};
    mj_objectVelocity(model, data, mjOBJ_BODY, id, velocity, 0);
    object_velocities_[o] = {velocity[3], velocity[4], velocity[5]};
  }
}

void TrackingEnv::WriteObservation(float* observation) {
  ReadBodyKinematics();
  WriteProprioception(bodies_, observation);
  if (layout_.num_objects > 0) {
    WriteObjectState(bodies_, object_positions_, object_velocities_,
                     observation + layout_.proprioception_size());
  }
  if (layout_.critic_only_size > 0) WriteCriticOnlyBlock(observation);
  const int num_points = layout_.num_points;
  if (options_.target == TrackingTarget::kBody3D) {
    // The 3D block: the character's keypoints and objects, then L future
    // reference frames' keypoints and objects, relative to the character's
    // root and heading.
    const Eigen::Vector3d& root = bodies_.positions_m[0];
    const Eigen::Quaterniond to_heading =
        InverseHeadingRotation(bodies_.orientations[0]);
    float* out = observation + layout_.view_offset();
    const int stride = num_points * ObservationLayout::kPointFeatures;
    // Points are 3 floats each, keypoints first: the objects follow them.
    const int num_objects = layout_.num_objects;
    const int num_keypoints = num_points - num_objects;
    const int objects_offset = 3 * num_keypoints;
    for (int j = 0; j < num_keypoints; ++j) {
      current_points_m_[j] = {keypoints_xyz_[3 * j], keypoints_xyz_[3 * j + 1],
                              keypoints_xyz_[3 * j + 2]};
    }
    WriteRootRelativePoints(current_points_m_.data(), num_keypoints, root,
                            to_heading, out);
    WriteRootRelativePoints(object_positions_.data(), num_objects, root,
                            to_heading, out + objects_offset);
    for (int l = 1; l <= layout_.num_future_frames; ++l) {
      const BodyTarget3D& future =
          ReferenceBody(std::min(frame_ + l, view_->num_frames - 1));
      WriteRootRelativePoints(future.keypoints_m.data(), num_keypoints, root,
                              to_heading, out + l * stride);
      WriteRootRelativePoints(future.object_positions_m.data(), num_objects,
                              root, to_heading,
                              out + l * stride + objects_offset);
    }
    return;
  }
  // One 2D block per observed view: the current projection, then L future
  // reference frames, all in the view's current image normalization.
  const int stride = num_points * ObservationLayout::kPointFeatures;
  for (int k = 0; k < num_observed_views_; ++k) {
    const TrackedView& view = *observed_views_[k];
    const ImageNormalization& normalization = view.normalization[frame_];
    float* out = observation + layout_.view_offset() + k * layout_.view_size();
    WriteNormalizedPoints(projected_points_.data() + k * num_points, num_points,
                          normalization, out);
    for (int l = 1; l <= layout_.num_future_frames; ++l) {
      int future = std::min(frame_ + l, view.num_frames - 1);
      WriteNormalizedPoints(view.frame(future), num_points, normalization,
                            out + l * stride);
    }
  }
}

void TrackingEnv::WriteCriticOnlyBlock(float* observation) const {
  // Without a 3D reference (default starts; a streamed reference, which has
  // no initial states) the block is zeros: the policy does not read it, and
  // training refuses such a config (TrainConfig::Validate).
  float* out = observation + layout_.actor_base_size();
  if (initial_states_ == nullptr ||
      reference_->sources().initial_states == InitialStateSource::kDefault) {
    std::fill(out, out + layout_.critic_only_size, 0.0f);
    return;
  }
  const BodyTarget3D& now = ReferenceBody(frame_);
  const BodyTarget3D& next = ReferenceBody(frame_ + 1);
  const PinholeCamera& camera = cameras_.front();
  WriteCriticOnlyInputs(
      bodies_, now.keypoints_m.data(), next.keypoints_m.data(),
      static_cast<int>(now.keypoints_m.size()), camera.CenterWorld(),
      camera.rotation_world_to_camera().transpose(), out);
}

}  // namespace m2d
