#include "env/tracking_env.h"

#include <algorithm>

#include "common/error.h"

namespace m2d {

void TrackingEnvOptions::Validate() const { CheckRanges(*this, "env"); }

TrackingEnv::TrackingEnv(std::shared_ptr<const Character> character,
                         std::shared_ptr<const TrackingReference> reference,
                         std::shared_ptr<const InitialStates> initial_states,
                         const TrackingEnvOptions& options, uint64_t seed)
    : reference_(std::move(reference)),
      initial_states_(std::move(initial_states)),
      options_(options),
      simulation_(character, options.simulation),
      rng_(seed) {
  options_.Validate();
  layout_.num_bodies = static_cast<int>(character->bodies().size());
  layout_.num_objects = reference_->num_object_points();
  layout_.num_points = reference_->num_points();
  layout_.num_future_frames = options_.num_future_frames;

  const int num_points = reference_->num_points();
  const int num_keypoints = character->keypoint_layout().num_keypoints();
  keypoints_xyz_.resize(3 * num_keypoints);
  projected_xy_.resize(2 * num_points);
  in_front_.reset(new bool[num_points]);
  projected_points_.resize(num_points);
  const size_t num_bodies = character->bodies().size();
  bodies_.positions_m.resize(num_bodies);
  bodies_.orientations.resize(num_bodies);
  bodies_.linear_velocities_m_s.resize(num_bodies);
  bodies_.angular_velocities_rad_s.resize(num_bodies);
  object_positions_.resize(layout_.num_objects);
  object_velocities_.resize(layout_.num_objects);
}

void TrackingEnv::Reset(float* observation) {
  // Outline: pick a view uniformly, a start frame uniformly (leaving at
  // least one step), an initial state from that frame's buffer.
  const std::vector<TrackedView>& views = reference_->views();
  int view_index = std::uniform_int_distribution<int>(
      0, static_cast<int>(views.size()) - 1)(rng_);
  const TrackedView& view = views[view_index];
  int frame = std::uniform_int_distribution<int>(0, view.num_frames - 2)(rng_);
  const StateBuffer& buffer = initial_states_->BufferOfView(view_index);
  ResetTo(view_index, frame, buffer.Draw(frame, rng_), observation);
}

void TrackingEnv::ResetTo(int view_index, int frame, const SimState& state,
                          float* observation) {
  simulation_.Restore(state);
  BeginEpisode(view_index, frame);
  ProjectCurrentPoints();
  WriteObservation(observation);
}

void TrackingEnv::BeginEpisode(int view_index, int frame) {
  view_ = &reference_->views()[view_index];
  frame_ = frame;
  episode_ = EpisodeStats();
  episode_.view_index = view_index;
  episode_.start_frame = frame;
}

StepOutcome TrackingEnv::Step(const float* action, float* observation) {
  // Outline: physics, advance the reference, measure the reprojection,
  // reward, decide whether the episode ends, observe.
  StepOutcome outcome;
  StepResult physics = simulation_.Step(action);
  ++frame_;
  ++episode_.steps;
  if (physics.diverged()) {
    outcome.terminated = outcome.diverged = true;
    episode_.failed = true;
    return outcome;
  }
  ProjectCurrentPoints();
  const int num_keypoints =
      simulation_.character().keypoint_layout().num_keypoints();
  const Keypoint2D* target = view_->frame(frame_);
  outcome.error = MeasureReprojection(projected_xy_.data(), in_front_.get(),
                                      target, num_keypoints);
  ReprojectionError object_error;
  if (layout_.num_objects > 0) {
    object_error =
        MeasureReprojection(projected_xy_.data() + 2 * num_keypoints,
                            in_front_.get() + num_keypoints,
                            target + num_keypoints, layout_.num_objects);
  }
  outcome.terms = ComputeReward(
      outcome.error, physics.mean_abs_power_w,
      layout_.num_objects > 0 ? &object_error : nullptr, options_.reward);
  outcome.reward = static_cast<float>(outcome.terms.total);

  episode_.total_reward += outcome.terms.total;
  if (outcome.error.num_present > 0) {
    ++episode_.measured_steps;
    episode_.sum_mean_error_px += outcome.error.mean_px;
  }
  episode_.max_error_px = std::max(episode_.max_error_px, outcome.error.max_px);

  if (options_.early_exit &&
      ShouldExitEarly(outcome.error, options_.early_exit_max_error_px)) {
    outcome.terminated = true;
    episode_.failed = true;
    return outcome;
  }
  if (frame_ >= view_->num_frames - 1 ||
      episode_.steps >= options_.max_episode_steps()) {
    outcome.truncated = true;
  }
  WriteObservation(observation);
  return outcome;
}

void TrackingEnv::ProjectCurrentPoints() {
  const mjData* data = simulation_.data();
  simulation_.KeypointPositions(keypoints_xyz_.data());
  const PinholeCamera& camera =
      reference_->bundles()[view_->bundle].views[view_->view].CameraAt(frame_);
  const int num_keypoints = static_cast<int>(keypoints_xyz_.size() / 3);
  for (int j = 0; j < view_->num_points; ++j) {
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
    projected_xy_[2 * j] = projection.pixel_px.x();
    projected_xy_[2 * j + 1] = projection.pixel_px.y();
    in_front_[j] = projection.in_front;
    projected_points_[j] = {projection.pixel_px.x(), projection.pixel_px.y(),
                            projection.in_front ? 1.0 : 0.0};
  }
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
  // 2D block: the current projection, then L future reference frames, all
  // in the current reference frame's image normalization.
  const ImageNormalization& normalization = view_->normalization[frame_];
  float* out = observation + layout_.view_offset();
  const int stride = view_->num_points * ObservationLayout::kPointFeatures;
  WriteNormalizedPoints(projected_points_.data(), view_->num_points,
                        normalization, out);
  for (int l = 1; l <= layout_.num_future_frames; ++l) {
    int future = std::min(frame_ + l, view_->num_frames - 1);
    WriteNormalizedPoints(view_->frame(future), view_->num_points,
                          normalization, out + l * stride);
  }
}

}  // namespace m2d
