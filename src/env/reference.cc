#include "env/reference.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "common/error.h"
#include "common/hash.h"
#include "motion/canonical.h"
#include "motion/object_track.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

// Mean of the layout's root keypoints and RMS spread of all keypoints, in
// metres, for 3D keypoints (the 3D analogue of RootAndScale).
void RootAndScale3D(const std::vector<Eigen::Vector3d>& keypoints,
                    const KeypointLayout& layout, Eigen::Vector3d* root,
                    double* scale_m) {
  *root = Eigen::Vector3d::Zero();
  for (int index : layout.root_keypoints) *root += keypoints[index];
  *root /= static_cast<double>(layout.root_keypoints.size());
  double squared = 0.0;
  for (const Eigen::Vector3d& point : keypoints)
    squared += (point - *root).squaredNorm();
  *scale_m = std::sqrt(squared / keypoints.size());
}

// The model's default pose, turned to face the camera and moved so that its
// root keypoints project onto the 2D root, at the height they have standing.
Pose3D PlaceDefaultPose(const Character& character, const Pose3D& standing,
                        const std::vector<Eigen::Vector3d>& standing_keypoints,
                        const PinholeCamera& camera,
                        const ImageNormalization& image) {
  Eigen::Vector3d root3d;
  double scale_m;
  RootAndScale3D(standing_keypoints, character.keypoint_layout(), &root3d,
                 &scale_m);
  // The ray through the 2D root, in world coordinates.
  const Intrinsics& k = camera.intrinsics();
  const Eigen::Vector3d direction = camera.RayDirectionWorld(image.root_px);
  Eigen::Vector3d centre = camera.CenterWorld();
  // Meet the plane at the standing root height; for a ray nearly parallel to
  // the floor, use the depth at which the 3D spread has the 2D scale.
  double depth_along = 0.0;
  if (std::abs(direction.z()) > 1e-3)
    depth_along = (root3d.z() - centre.z()) / direction.z();
  if (!(depth_along > 0)) depth_along = k.fx_px * scale_m / image.scale_px;
  Eigen::Vector3d target = centre + depth_along * direction;

  Pose3D pose = standing;
  Eigen::Vector3d to_camera = centre - target;
  double yaw = std::atan2(to_camera.y(), to_camera.x());
  Eigen::Quaterniond turn(
      Eigen::AngleAxisd(yaw - HeadingAngle(standing.local_rotations[0]),
                        Eigen::Vector3d::UnitZ()));
  pose.local_rotations[0] = turn * standing.local_rotations[0];
  Eigen::Vector3d root_offset = turn * (root3d - standing.root_position_m);
  pose.root_position_m = target - root_offset;
  pose.root_position_m.z() = standing.root_position_m.z();
  return pose;
}

// Moves the character up by `height_m` (down when negative), keeping its
// pose.
void RaiseCharacter(double height_m, Simulation& simulation) {
  simulation.mutable_data()
      ->qpos[simulation.character().root_qpos_address() + 2] += height_m;
  simulation.Refresh();
}

// Noisy S.I.: adds N(0, sigma) to every actuated hinge angle (kept within
// the hinge's range), then moves the character vertically so that its
// lowest point is where it was. Otherwise a leg bent by the noise would
// start inside the floor (up to 6 cm on the walk at sigma 0.5), a state
// that no motion reaches.
void AddJointNoise(double sigma_rad, std::mt19937_64& rng,
                   Simulation& simulation) {
  const Character& character = simulation.character();
  const double lowest_before_m = LowestCharacterPointZ(simulation);
  mjData* data = simulation.mutable_data();
  std::normal_distribution<double> noise(0.0, sigma_rad);
  for (const ActuatedHinge& hinge : character.hinges()) {
    double& angle_rad = data->qpos[hinge.qpos_address];
    angle_rad = std::clamp(angle_rad + noise(rng), hinge.range_low_rad,
                           hinge.range_high_rad);
  }
  simulation.Refresh();
  RaiseCharacter(lowest_before_m - LowestCharacterPointZ(simulation),
                 simulation);
}

// The 3D tracks of the reference's objects (object point order) that a
// buffer's starts take their objects from: the truth's, the view's
// estimate's, or (default) the view's 2D put on the floor through its
// cameras (RollingObjectFromPixels).
std::vector<ObjectTrack3D> StartObjectTracks(const ReferenceBundle& bundle,
                                             int view,
                                             InitialStateSource source,
                                             const Character& character) {
  std::vector<ObjectTrack3D> tracks;
  const ReferenceView& reference_view = bundle.views[view];
  for (const ObjectTrack2D& object : reference_view.clip.objects) {
    const ObjectTrack3D* found = nullptr;
    switch (source) {
      case InitialStateSource::kTruth:
        found = FindObjectTrack(bundle.ground_truth->objects, object.name);
        break;
      case InitialStateSource::kEstimate:
        found = FindObjectTrack((*bundle.estimate)[view].objects, object.name);
        break;
      case InitialStateSource::kDefault: {
        RollingBall ball;
        for (const FreeObject& free : character.free_objects()) {
          if (free.name == object.name) ball.radius_m = free.radius_m;
        }
        tracks.push_back(RollingObjectFromPixels(
            object, reference_view.cameras, bundle.fps, ball, bundle.name));
        continue;
      }
    }
    tracks.push_back(*found);  // SanitizeBundle checked that it exists
  }
  return tracks;
}

// Puts each free object of `tracks` (object point order; `object_bodies`
// their model bodies) at frame `t`, moving at the track's central
// differences; an object within 1 cm of resting on the floor also spins as
// a ball rolling without slipping.
void PlaceObjects(const std::vector<ObjectTrack3D>& tracks,
                  const std::vector<int>& object_bodies, int t, double dt_s,
                  Simulation& simulation) {
  if (tracks.empty()) return;  // the state stays exactly as set
  const Character& character = simulation.character();
  mjData* data = simulation.mutable_data();
  for (size_t o = 0; o < tracks.size(); ++o) {
    const FreeObject* object = nullptr;
    for (const FreeObject& free : character.free_objects()) {
      if (free.body_id == object_bodies[o]) object = &free;
    }
    const std::vector<Eigen::Vector3d>& path = tracks[o].positions_m;
    const int previous = std::max(t - 1, 0);
    const int next = std::min(t + 1, static_cast<int>(path.size()) - 1);
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    if (next > previous)
      velocity = (path[next] - path[previous]) / ((next - previous) * dt_s);
    double* qpos = data->qpos + object->qpos_address;
    double* qvel = data->qvel + object->dof_address;
    for (int i = 0; i < 3; ++i) {
      qpos[i] = path[t][i];
      qvel[i] = velocity[i];
      qvel[3 + i] = 0.0;
    }
    qpos[3] = 1.0;
    qpos[4] = qpos[5] = qpos[6] = 0.0;
    if (object->radius_m > 0 && path[t].z() < object->radius_m + 0.01) {
      // Rolling: omega = z x v / r (a free joint's angular velocity is in
      // the body frame, which is the world's at the identity orientation).
      qvel[3] = -velocity.y() / object->radius_m;
      qvel[4] = velocity.x() / object->radius_m;
    }
  }
  simulation.Refresh();
}

// Keeps of `bundle` only what `sources` allow downstream (see Prepare);
// InputError naming the bundle when a source is missing.
void SanitizeBundle(const Character& character, const TaskSources& sources,
                    ReferenceBundle* bundle) {
  const std::string& skeleton = character.skeleton().name;
  const bool wants_estimate =
      sources.initial_states == InitialStateSource::kEstimate ||
      sources.cameras == CameraSource::kEstimate;
  if (wants_estimate && !bundle->estimate) {
    throw InputError(bundle->name,
                     std::string("initial_states: ") +
                         SourceName(sources.initial_states) +
                         ", cameras: " + SourceName(sources.cameras) +
                         " need an estimate and the bundle has none: run "
                         "mimic2d fit on it");
  }
  if (sources.initial_states == InitialStateSource::kTruth) {
    const GroundTruth3D* truth =
        bundle->ground_truth ? &*bundle->ground_truth : nullptr;
    if (truth == nullptr || truth->poses.empty()) {
      throw InputError(bundle->name,
                       "initial_states: truth needs ground-truth poses and "
                       "the bundle has none (use initial_states: estimate "
                       "after mimic2d fit, or default)");
    }
    if (truth->skeleton_name != skeleton) {
      throw InputError(bundle->name, "ground-truth poses are of skeleton '" +
                                         truth->skeleton_name +
                                         "', the character's is '" + skeleton +
                                         "': initial_states: truth cannot "
                                         "replay them");
    }
    for (const ObjectTrack2D& object : bundle->views.front().clip.objects) {
      if (FindObjectTrack(truth->objects, object.name) == nullptr) {
        throw InputError(bundle->name,
                         "initial_states: truth needs the 3D of object '" +
                             object.name +
                             "' and the ground truth has none (use "
                             "initial_states: estimate after mimic2d fit)");
      }
    }
  } else {
    bundle->ground_truth.reset();
  }
  if (sources.cameras == CameraSource::kTruth) {
    for (const ReferenceView& view : bundle->views) {
      if (view.cameras.empty()) {
        throw InputError(bundle->name,
                         "view " + view.name +
                             " has no true cameras (stripped? use cameras: "
                             "estimate)");
      }
    }
  } else {
    for (size_t v = 0; v < bundle->views.size(); ++v)
      bundle->views[v].cameras = (*bundle->estimate)[v].cameras;
  }
  if (sources.initial_states == InitialStateSource::kEstimate) {
    for (size_t v = 0; v < bundle->views.size(); ++v) {
      const ViewEstimate& estimate = (*bundle->estimate)[v];
      if (estimate.skeleton_name != skeleton) {
        throw InputError(bundle->name,
                         "the estimate of view " + bundle->views[v].name +
                             " is of skeleton '" + estimate.skeleton_name +
                             "', the character's is '" + skeleton +
                             "': fit it again for this character");
      }
      for (const ObjectTrack2D& object : bundle->views[v].clip.objects) {
        if (FindObjectTrack(estimate.objects, object.name) == nullptr) {
          throw InputError(bundle->name,
                           "the estimate of view " + bundle->views[v].name +
                               " has no 3D of object '" + object.name +
                               "': fit it again (mimic2d fit "
                               "places the objects)");
        }
      }
    }
  } else {
    bundle->estimate.reset();
  }
}

// Central differences (one-sided at the ends) of `poses` around frame `t`:
// second-order accurate, and a one-frame glitch in the recording (the
// DeepMimic walk's mirrored half-cycles meet with a 0.5 rad shoulder jump)
// gives half the spurious velocity of a forward difference.
void QvelAtFrame(const Character& character, const std::vector<Pose3D>& poses,
                 int t, double dt_s, std::vector<double>* qvel) {
  const int previous = std::max(t - 1, 0);
  const int next = std::min(t + 1, static_cast<int>(poses.size()) - 1);
  std::fill(qvel->begin(), qvel->end(), 0.0);
  if (next > previous) {
    QvelFromPoses(character, poses[previous], poses[next],
                  (next - previous) * dt_s, qvel->data(), &poses[t]);
  }
}

// Puts the character in fitted pose `t` of `poses`, moving at their central
// differences, lifted out of the floor when the pose grazes it (never
// lowered). `qvel` is scratch of the model's nv.
void SetEstimatedPose(const std::vector<Pose3D>& poses, int t, double dt_s,
                      std::vector<double>* qvel, Simulation& simulation) {
  QvelAtFrame(simulation.character(), poses, t, dt_s, qvel);
  simulation.SetPose(poses[t], qvel->data());
  RaiseCharacter(std::max(0.0, -LowestCharacterPointZ(simulation)), simulation);
}

// A rotation from MuJoCo's (w, x, y, z) quaternion layout.
Eigen::Quaterniond MujocoRotation(const double* wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
}

}  // namespace

std::shared_ptr<const TrackingReference> TrackingReference::Prepare(
    std::vector<ReferenceBundle> bundles, const Character& character,
    double control_hz, const TaskSources& sources) {
  auto reference = std::shared_ptr<TrackingReference>(new TrackingReference());
  if (bundles.empty()) throw InputError("", "no reference bundles to track");
  try {
    sources.Validate();
  } catch (const ConfigError& e) {
    throw InputError("sources", e.what());
  }
  reference->sources_ = sources;
  for (ReferenceBundle& bundle : bundles)
    SanitizeBundle(character, sources, &bundle);
  const KeypointLayout& layout = character.keypoint_layout();
  const std::vector<FreeObject>& objects = character.free_objects();

  // Object points: the first bundle's object tracks, each naming one of the
  // scene's free objects; every bundle must track the same ones.
  const Clip2D& first_clip = bundles[0].views[0].clip;
  for (const ObjectTrack2D& track : first_clip.objects) {
    int body = -1;
    for (const FreeObject& object : objects) {
      if (object.name == track.name) body = object.body_id;
    }
    if (body < 0) {
      throw InputError(bundles[0].name,
                       "object track '" + track.name +
                           "' has no free body of that name in the scene");
    }
    reference->object_bodies_.push_back(body);
  }
  reference->num_object_points_ = static_cast<int>(first_clip.objects.size());
  reference->num_points_ =
      layout.num_keypoints() + reference->num_object_points_;

  for (size_t b = 0; b < bundles.size(); ++b) {
    const ReferenceBundle& bundle = bundles[b];
    if (std::abs(bundle.fps - control_hz) > 1e-6) {
      throw InputError(bundle.name,
                       "bundle is at " + std::to_string(bundle.fps) +
                           " fps but the controller runs at " +
                           std::to_string(control_hz) +
                           " Hz: make the bundle at the control rate");
    }
    if (bundle.num_frames() < 2)
      throw InputError(bundle.name, "needs at least 2 frames");
    for (size_t v = 0; v < bundle.views.size(); ++v) {
      const Clip2D& clip = bundle.views[v].clip;
      std::string where = bundle.name + " view " + bundle.views[v].name;
      if (clip.layout != &layout) {
        throw InputError(where, "layout " + clip.layout->name +
                                    " differs from the character's " +
                                    layout.name);
      }
      if (clip.objects.size() != first_clip.objects.size()) {
        throw InputError(
            where, "tracks a different set of objects than the first bundle");
      }
      TrackedView view;
      view.bundle = static_cast<int>(b);
      view.view = static_cast<int>(v);
      view.num_frames = clip.num_frames();
      view.num_points = reference->num_points_;
      view.points.reserve(static_cast<size_t>(view.num_frames) *
                          view.num_points);
      for (int t = 0; t < view.num_frames; ++t) {
        for (int j = 0; j < layout.num_keypoints(); ++j)
          view.points.push_back(clip.keypoints.at(t, j));
        for (size_t o = 0; o < clip.objects.size(); ++o) {
          if (clip.objects[o].name != first_clip.objects[o].name) {
            throw InputError(where, "object " + std::to_string(o) + " is '" +
                                        clip.objects[o].name + "', expected '" +
                                        first_clip.objects[o].name + "'");
          }
          view.points.push_back(clip.objects[o].points[t]);
        }
      }
      std::vector<Eigen::Vector2d> roots;
      std::vector<double> scales;
      FrameRootsAndScales(clip, where, &roots, &scales);
      for (int t = 0; t < view.num_frames; ++t)
        view.normalization.push_back({roots[t], scales[t]});
      reference->views_.push_back(std::move(view));
    }
  }
  reference->bundles_ = std::move(bundles);
  return reference;
}

uint64_t ReferenceFingerprint(const TrackingReference& reference) {
  uint64_t hash = kFnv1a64Seed;
  for (const TrackedView& view : reference.views()) {
    const int64_t shape[2] = {view.num_frames, view.num_points};
    hash = Fnv1a64(shape, sizeof(shape), hash);
    for (const Keypoint2D& point : view.points) {
      const double values[3] = {point.x_px, point.y_px, point.confidence};
      hash = Fnv1a64(values, sizeof(values), hash);
    }
  }
  return hash;
}

void ReadBodyTarget(const Simulation& simulation, const double* keypoints_xyz,
                    BodyTarget3D* target) {
  const Character& character = simulation.character();
  const mjData* data = simulation.data();
  const double* root_qpos = data->qpos + character.root_qpos_address();
  const double* root_qvel = data->qvel + character.root_dof_address();
  target->root_position_m = {root_qpos[0], root_qpos[1], root_qpos[2]};
  target->root_orientation = MujocoRotation(root_qpos + 3);
  target->root_linear_velocity_m_s = {root_qvel[0], root_qvel[1], root_qvel[2]};
  target->root_angular_velocity_rad_s = {root_qvel[3], root_qvel[4],
                                         root_qvel[5]};
  // Each moving joint from its body and the parent's: rotation q_p^-1 q_c
  // (xquat), angular velocity R_p^T (w_c - w_p) (cvel's rotational part is
  // in world axes). Both are current after mj_step1 / Refresh.
  const int* parent_of = simulation.model()->body_parentid;
  target->joint_rotations.clear();
  target->joint_angular_velocities_rad_s.clear();
  for (const BoundJoint& joint : character.joints()) {
    if (joint.type != JointType::kSpherical &&
        joint.type != JointType::kRevolute) {
      continue;
    }
    const int body = joint.body_id, parent = parent_of[joint.body_id];
    const Eigen::Quaterniond parent_rotation =
        MujocoRotation(data->xquat + 4 * parent);
    target->joint_rotations.push_back(parent_rotation.conjugate() *
                                      MujocoRotation(data->xquat + 4 * body));
    const Eigen::Map<const Eigen::Vector3d> child_w(data->cvel + 6 * body);
    const Eigen::Map<const Eigen::Vector3d> parent_w(data->cvel + 6 * parent);
    target->joint_angular_velocities_rad_s.push_back(
        parent_rotation.conjugate() * (child_w - parent_w));
  }
  const int num_keypoints = character.keypoint_layout().num_keypoints();
  target->keypoints_m.resize(num_keypoints);
  for (int k = 0; k < num_keypoints; ++k) {
    target->keypoints_m[k] = {keypoints_xyz[3 * k], keypoints_xyz[3 * k + 1],
                              keypoints_xyz[3 * k + 2]};
  }
}

InitialStates::InitialStates(const TrackingReference& reference,
                             std::shared_ptr<const Character> character,
                             const SimulationOptions& simulation_options,
                             const StateBufferOptions& options,
                             double joint_noise_rad, uint64_t noise_seed) {
  reference_fingerprint_ = ReferenceFingerprint(reference);
  // Outline: per buffer (a bundle's, or with an estimate a view's), per
  // frame, put the character in a plausible pose (3D truth, the view's
  // estimate, or a placed default pose), perturb its joints if asked, and
  // keep the state.
  if (!(joint_noise_rad >= 0)) {
    throw ConfigError("initial-state joint noise must be >= 0 rad");
  }
  Simulation simulation(character, simulation_options);
  std::mt19937_64 noise_rng(noise_seed);
  const double dt_s = 1.0 / simulation_options.control_hz;
  simulation.Reset();
  Pose3D standing = QposToPose(*character, simulation.data()->qpos);
  std::vector<Eigen::Vector3d> standing_keypoints =
      SimulatedKeypoints(simulation);
  std::vector<double> qvel(character->model()->nv, 0.0);
  std::vector<double> keypoints_xyz(
      3 * character->keypoint_layout().num_keypoints());
  const InitialStateSource source = reference.sources().initial_states;
  const std::vector<TrackedView>& views = reference.views();

  // Which views share a buffer: all of a bundle's, or each its own.
  std::vector<int> first_view_of_buffer;
  for (size_t v = 0; v < views.size(); ++v) {
    const bool new_buffer = source == InitialStateSource::kEstimate || v == 0 ||
                            views[v].bundle != views[v - 1].bundle;
    if (new_buffer) first_view_of_buffer.push_back(static_cast<int>(v));
    buffer_of_view_.push_back(static_cast<int>(first_view_of_buffer.size()) -
                              1);
  }

  for (int first : first_view_of_buffer) {
    const TrackedView& view = views[first];
    const ReferenceBundle& bundle = reference.bundles()[view.bundle];
    StateBuffer buffer(bundle.num_frames(), options);
    std::vector<BodyTarget3D> motion(bundle.num_frames());
    const std::vector<ObjectTrack3D> object_tracks =
        StartObjectTracks(bundle, view.view, source, *character);
    for (int t = 0; t < bundle.num_frames(); ++t) {
      simulation.Reset();
      switch (source) {
        case InitialStateSource::kTruth: {
          const std::vector<Pose3D>& poses = bundle.ground_truth->poses;
          QvelAtFrame(*character, poses, t, dt_s, &qvel);
          simulation.SetPose(poses[t], qvel.data());
          break;
        }
        case InitialStateSource::kEstimate:
          SetEstimatedPose((*bundle.estimate)[view.view].poses, t, dt_s, &qvel,
                           simulation);
          break;
        case InitialStateSource::kDefault:
          // Placed from the bundle's first view.
          simulation.SetPose(PlaceDefaultPose(
              *character, standing, standing_keypoints,
              bundle.views[view.view].CameraAt(t), view.normalization[t]));
          break;
      }
      PlaceObjects(object_tracks, reference.object_bodies(), t, dt_s,
                   simulation);
      simulation.KeypointPositions(keypoints_xyz.data());
      ReadBodyTarget(simulation, keypoints_xyz.data(), &motion[t]);
      for (const ObjectTrack3D& track : object_tracks)
        motion[t].object_positions_m.push_back(track.positions_m[t]);
      if (joint_noise_rad > 0)
        AddJointNoise(joint_noise_rad, noise_rng, simulation);
      const SimState filled = simulation.Save();
      buffer.Insert(t, filled, 0.0);
      buffer.SetAnchor(t, filled);
    }
    buffers_.push_back(std::move(buffer));
    motions_.push_back(std::move(motion));
  }
}

SimState EstimatedState(std::shared_ptr<const Character> character,
                        const SimulationOptions& simulation_options,
                        const std::vector<Pose3D>& poses, int frame) {
  if (frame < 0 || frame >= static_cast<int>(poses.size())) {
    throw ConfigError("EstimatedState: frame " + std::to_string(frame) +
                      " of " + std::to_string(poses.size()) + " poses");
  }
  Simulation simulation(character, simulation_options);
  simulation.Reset();
  std::vector<double> qvel(character->model()->nv, 0.0);
  SetEstimatedPose(poses, frame, 1.0 / simulation_options.control_hz, &qvel,
                   simulation);
  return simulation.Save();
}

SimState PlacedDefaultState(std::shared_ptr<const Character> character,
                            const SimulationOptions& simulation_options,
                            const PinholeCamera& camera,
                            const ImageNormalization& image) {
  Simulation simulation(character, simulation_options);
  simulation.Reset();
  const Pose3D standing = QposToPose(*character, simulation.data()->qpos);
  simulation.SetPose(PlaceDefaultPose(
      *character, standing, SimulatedKeypoints(simulation), camera, image));
  return simulation.Save();
}

void InitialStates::SetViewWeights(const std::vector<double>& weights) {
  if (static_cast<int>(weights.size()) != num_views()) {
    throw ConfigError("initial states: " + std::to_string(weights.size()) +
                      " view weights for " + std::to_string(num_views()) +
                      " views");
  }
  std::vector<double> cumulative;
  double total = 0.0;
  for (double weight : weights) {
    if (!std::isfinite(weight) || weight < 0.0) {
      throw ConfigError("initial states: a view weight is " +
                        std::to_string(weight) + " (finite, >= 0 expected)");
    }
    total += weight;
    cumulative.push_back(total);
  }
  if (total <= 0.0) {
    throw ConfigError("initial states: every view weight is 0");
  }
  view_cumulative_weights_ = std::move(cumulative);
}

int InitialStates::DrawView(std::mt19937_64& rng) const {
  if (view_cumulative_weights_.empty()) {
    return std::uniform_int_distribution<int>(0, num_views() - 1)(rng);
  }
  const double u = std::uniform_real_distribution<double>(
      0.0, view_cumulative_weights_.back())(rng);
  const auto it = std::upper_bound(view_cumulative_weights_.begin(),
                                   view_cumulative_weights_.end(), u);
  return std::min(static_cast<int>(it - view_cumulative_weights_.begin()),
                  num_views() - 1);
}

}  // namespace m2d
