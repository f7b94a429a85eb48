#include "fit/fit.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "common/error.h"
#include "fit/camera_model.h"
#include "fit/costs.h"
#include "fit/kinematics.h"
#include "fit/pose_prior.h"
#include "fit/pose_prior_training.h"
#include "motion/canonical.h"
#include "motion/object_track.h"
#include "sim/character.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

// The clip as the fit uses it: confident keypoints with their weights, and
// per frame the person's root and size in the image.
struct Observations {
  int num_frames = 0;
  int num_keypoints = 0;
  int width_px = 0;
  int height_px = 0;
  double fps = 30.0;
  std::vector<Eigen::Vector2d> pixel_px;  // T x J, frame-major
  std::vector<double> weight;             // T x J: confidence, 0 = unused
  std::vector<char> usable;               // per frame: enough keypoints
  std::vector<Eigen::Vector2d> root_px;   // per frame (gaps carried over)
  std::vector<double> scale_px;           // per frame: RMS keypoint spread
  double median_scale_px = 0.0;

  double Weight(int t, int j) const { return weight[t * num_keypoints + j]; }
  const Eigen::Vector2d& Pixel(int t, int j) const {
    return pixel_px[t * num_keypoints + j];
  }
};

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

Observations ReadObservations(const Clip2D& clip, const FitOptions& options,
                              const std::string& source) {
  // Outline: reject clips the fit cannot use (too short, coordinates far
  // outside the image, too few usable frames, a tiny person), keep the
  // confident keypoints, measure each frame's root and size.
  Observations obs;
  obs.num_frames = clip.num_frames();
  obs.num_keypoints = clip.layout->num_keypoints();
  obs.width_px = clip.image_width_px;
  obs.height_px = clip.image_height_px;
  obs.fps = clip.fps;
  if (obs.num_frames < options.min_frames) {
    throw InputError(source, "clip has " + std::to_string(obs.num_frames) +
                                 " frames; the fit needs at least " +
                                 std::to_string(options.min_frames));
  }
  obs.pixel_px.resize(static_cast<size_t>(obs.num_frames) * obs.num_keypoints);
  obs.weight.assign(obs.pixel_px.size(), 0.0);
  obs.usable.assign(obs.num_frames, 0);
  int num_usable = 0;
  for (int t = 0; t < obs.num_frames; ++t) {
    int confident = 0;
    for (int j = 0; j < obs.num_keypoints; ++j) {
      const Keypoint2D& point = clip.keypoints.at(t, j);
      if (!point.IsPresent()) continue;
      if (!std::isfinite(point.x_px) || !std::isfinite(point.y_px)) {
        throw InputError(source, "frame " + std::to_string(t) + " keypoint " +
                                     clip.layout->keypoint_names[j] +
                                     " has a non-finite coordinate");
      }
      // A detector may place a keypoint a little outside the image; one an
      // image size away is a broken file, not a detection.
      if (point.x_px < -obs.width_px || point.x_px > 2.0 * obs.width_px ||
          point.y_px < -obs.height_px || point.y_px > 2.0 * obs.height_px) {
        char where[160];
        std::snprintf(where, sizeof(where),
                      "frame %d keypoint %s at (%.0f, %.0f) px is far "
                      "outside the %dx%d image",
                      t, clip.layout->keypoint_names[j].c_str(), point.x_px,
                      point.y_px, obs.width_px, obs.height_px);
        throw InputError(source, where);
      }
      obs.pixel_px[t * obs.num_keypoints + j] = point.Pixel();
      if (point.confidence >= options.min_confidence) {
        obs.weight[t * obs.num_keypoints + j] = point.confidence;
        ++confident;
      }
    }
    if (confident >= options.min_keypoints_per_frame) {
      obs.usable[t] = 1;
      ++num_usable;
    } else {
      for (int j = 0; j < obs.num_keypoints; ++j)
        obs.weight[t * obs.num_keypoints + j] = 0.0;
    }
  }
  if (num_usable < options.min_usable_fraction * obs.num_frames) {
    char problem[200];
    std::snprintf(problem, sizeof(problem),
                  "only %d of %d frames have %d or more keypoints with "
                  "confidence >= %.2f; the fit needs %.0f%% of the frames",
                  num_usable, obs.num_frames, options.min_keypoints_per_frame,
                  options.min_confidence, 100.0 * options.min_usable_fraction);
    throw InputError(source, problem);
  }
  FrameRootsAndScales(clip, source, &obs.root_px, &obs.scale_px);
  std::vector<double> usable_scales;
  for (int t = 0; t < obs.num_frames; ++t) {
    if (obs.usable[t]) usable_scales.push_back(obs.scale_px[t]);
  }
  obs.median_scale_px = Median(usable_scales);
  if (!(obs.median_scale_px >= options.min_person_scale_px)) {
    char problem[160];
    std::snprintf(problem, sizeof(problem),
                  "the person is only %.1f px in size (RMS keypoint spread); "
                  "the fit needs at least %.1f px",
                  obs.median_scale_px, options.min_person_scale_px);
    throw InputError(source, problem);
  }
  return obs;
}

// The clip's observations, checked to be in the character's layout.
Observations ReadCharacterObservations(const Clip2D& clip,
                                       const Character& character,
                                       const FitOptions& options,
                                       const std::string& source) {
  if (clip.layout != &character.keypoint_layout()) {
    throw InputError(source, "clip layout " + clip.layout->name +
                                 " differs from the character's " +
                                 character.keypoint_layout().name);
  }
  return ReadObservations(clip, options, source);
}

// The focal length's prior: the known one, or the image diagonal.
double FocalPriorPx(const FitOptions& options, const Observations& obs) {
  return options.fixed_focal_px > 0
             ? options.fixed_focal_px
             : std::hypot(static_cast<double>(obs.width_px), obs.height_px);
}

// Per frame, whether the ground term applies (defined below).
std::vector<char> GroundFrames(const Observations& obs,
                               const KinematicModel& model,
                               const KeypointLayout& layout,
                               const FitOptions& options);

// What the fit assumes beyond the 2D: the focal length's prior, the
// learned pose prior (null: the pull toward rest) and the frames where a
// foot can stand on the floor.
struct FitPriors {
  double focal_px = 0.0;
  std::shared_ptr<const PoseMixture> pose_mixture;
  std::string pose_prior_name = "rest";  // for the summary
  std::vector<char> ground_frames;       // per frame
};

FitPriors MakeFitPriors(const Character& character, const KinematicModel& model,
                        const KeypointLayout& layout, const FitOptions& options,
                        const Observations& obs, const std::string& source) {
  FitPriors priors;
  priors.focal_px = FocalPriorPx(options, obs);
  priors.ground_frames = GroundFrames(obs, model, layout, options);
  const std::string& path = character.config().pose_prior_path;
  if (options.pose_prior == PosePriorKind::kRest ||
      (options.pose_prior == PosePriorKind::kAuto && path.empty())) {
    return priors;
  }
  if (path.empty()) {
    throw InputError(source, "pose_prior is mixture but character '" +
                                 character.name() +
                                 "' names no pose_prior in its config");
  }
  auto mixture = std::make_shared<PoseMixture>(ReadPoseMixture(path));
  CheckPoseMixtureHinges(*mixture, HingeNames(character), path);
  priors.pose_mixture = std::move(mixture);
  priors.pose_prior_name =
      "mixture of " + std::to_string(priors.pose_mixture->num_components()) +
      " (" + path.substr(path.find_last_of('/') + 1) + ")";
  return priors;
}

// One camera's estimated quantities (camera_model.h).
struct CameraParameters {
  double focal_px = 0.0;
  double pitch_roll_rad[2] = {0.0, 0.0};
  // 0, the world's heading, but for a rig's other cameras (FitRig).
  double yaw_rad = 0.0;
  std::vector<Eigen::Vector3d> centres_m;  // 1 (static) or one per frame

  double* centre(int t) {
    return centres_m.size() == 1 ? centres_m[0].data() : centres_m[t].data();
  }
  const double* centre(int t) const {
    return centres_m.size() == 1 ? centres_m[0].data() : centres_m[t].data();
  }
  PinholeCamera ToPinhole(int c, const Observations& obs) const {
    return ToPinholeCamera(focal_px, pitch_roll_rad, centres_m[c].data(),
                           obs.width_px, obs.height_px, yaw_rad);
  }
};

// Every estimated quantity. Vectors are sized once, so block pointers stay
// valid while Ceres holds them.
struct Parameters {
  CameraParameters camera;
  // A synchronized rig's other cameras (FitRig), seeing the same body; empty
  // for one view.
  std::vector<CameraParameters> rig_cameras;
  std::vector<Eigen::Vector3d> root_m;
  std::vector<Eigen::Vector4d> quaternion_wxyz;
  std::vector<std::vector<double>> hinges_rad;

  double* centre(int t) { return camera.centre(t); }
  const double* centre(int t) const { return camera.centre(t); }
};

// The rest pose's keypoints (root at the origin, identity orientation, all
// hinges at their start value) and its image-size analogue: the RMS spread
// about the mean of the layout's root keypoints.
struct RestPose {
  std::vector<double> hinges_rad;
  std::vector<double> points;  // CharacterPoints at the origin
  Eigen::Vector3d root_keypoint_offset_m = Eigen::Vector3d::Zero();
  double scale_m = 0.0;
};

RestPose MakeRestPose(const KinematicModel& model,
                      const KeypointLayout& layout) {
  RestPose rest;
  for (int h = 0; h < model.num_hinges(); ++h) {
    rest.hinges_rad.push_back(
        std::clamp(0.0, model.hinge_low_rad[h], model.hinge_high_rad[h]));
  }
  const double origin[3] = {0, 0, 0};
  const double identity[4] = {1, 0, 0, 0};
  std::vector<double>& points = rest.points;
  points.resize(3 * (model.num_keypoints() + model.num_sole_points()));
  CharacterPoints(model, origin, identity, rest.hinges_rad.data(),
                  points.data());
  auto point = [&](int j) {
    return Eigen::Vector3d(points[3 * j], points[3 * j + 1], points[3 * j + 2]);
  };
  for (int index : layout.root_keypoints)
    rest.root_keypoint_offset_m += point(index);
  rest.root_keypoint_offset_m /=
      static_cast<double>(layout.root_keypoints.size());
  double squared = 0.0;
  for (int j = 0; j < model.num_keypoints(); ++j)
    squared += (point(j) - rest.root_keypoint_offset_m).squaredNorm();
  rest.scale_m = std::sqrt(squared / model.num_keypoints());
  return rest;
}

// A start: the rest pose standing on the ray through each frame's 2D root,
// at the depth where its size matches the 2D size, turned to `yaw_rad`; the
// camera pitched down by `pitch_rad`, without roll, at the height that puts
// the roots at standing height.
Parameters InitialParameters(const Observations& obs,
                             const KinematicModel& model, const RestPose& rest,
                             const FitOptions& options, double focal_px,
                             double yaw_rad, double pitch_rad) {
  Parameters params;
  params.camera.focal_px = focal_px;
  params.camera.pitch_roll_rad[0] = pitch_rad;
  if (options.tilt_known)
    params.camera.pitch_roll_rad[1] = options.known_roll_deg * M_PI / 180.0;
  const Eigen::Matrix3d rotation =
      FitCameraRotation(params.camera.pitch_roll_rad);
  const double cx = 0.5 * obs.width_px, cy = 0.5 * obs.height_px;
  // Each root relative to the camera centre, in the world's axes.
  std::vector<Eigen::Vector3d> from_camera_m(obs.num_frames);
  std::vector<double> drop_m;  // how far below the camera each root is
  for (int t = 0; t < obs.num_frames; ++t) {
    const double depth_m = focal_px * rest.scale_m / obs.scale_px[t];
    const Eigen::Vector3d ray_camera((obs.root_px[t].x() - cx) / focal_px,
                                     (obs.root_px[t].y() - cy) / focal_px, 1.0);
    from_camera_m[t] = rotation.transpose() * (depth_m * ray_camera);
    if (obs.usable[t]) drop_m.push_back(-from_camera_m[t].z());
  }
  const double root_height_m =
      model.standing_root_height_m + rest.root_keypoint_offset_m.z();
  const double height_m = std::clamp(root_height_m + Median(drop_m), 0.3, 30.0);
  const int num_centres =
      options.camera_motion == CameraMotion::kMoving ? obs.num_frames : 1;
  params.camera.centres_m.assign(num_centres, Eigen::Vector3d(0, 0, height_m));
  const Eigen::Quaterniond turn(
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
  for (int t = 0; t < obs.num_frames; ++t) {
    const Eigen::Vector3d root_keypoints =
        Eigen::Vector3d(params.centre(t)) + from_camera_m[t];
    params.root_m.push_back(root_keypoints -
                            turn * rest.root_keypoint_offset_m);
    params.quaternion_wxyz.emplace_back(turn.w(), turn.x(), turn.y(), turn.z());
    params.hinges_rad.push_back(rest.hinges_rad);
  }
  return params;
}

// Leg-odometry passes before each contact round of a moving camera.
constexpr int kOdometryPasses = 3;

enum class Stage {
  kRoot,  // camera + root trajectory, torso keypoints, rest pose held
  kPose,  // + every hinge and keypoint, pose prior
  kPoseWithContacts,  // + feet that do not slide while in contact
  kRefine,  // the same terms, the camera held, the final weights (stage 4)
};

bool HasContactTerms(Stage stage) {
  return stage == Stage::kPoseWithContacts || stage == Stage::kRefine;
}

// Every frame's keypoints then sole points in the world, 3 numbers each
// (T x (J + S) x 3).
std::vector<std::vector<double>> FramePoints(Parameters& params,
                                             const KinematicModel& model) {
  std::vector<std::vector<double>> points(params.root_m.size());
  for (size_t t = 0; t < points.size(); ++t) {
    points[t].resize(3 * (model.num_keypoints() + model.num_sole_points()));
    CharacterPoints(model, params.root_m[t].data(),
                    params.quaternion_wxyz[t].data(),
                    params.hinges_rad[t].data(), points[t].data());
  }
  return points;
}

// Per frame and sole point: how surely it touches the floor. Heights count
// from the frame's lowest sole point, so that only the lower foot holds: a
// swing foot skims the floor by a few centimetres, and labelling both feet
// would make walking in place (both sliding) as cheap as walking. With
// `gate_by_speed`, a sole point moving faster than `contact_speed_mps` to
// the next frame is not in contact either: a landing foot is the lowest a
// frame before it stops. With `feet_in_2d` (static camera, ObservedFeet
// below) a foot seen still or moving in the 2D is gated by that instead; an
// unseen one by its fitted speed as above.
using ContactWeights = std::vector<std::vector<double>>;
// What a foot's observed 2D ankle shows at a frame.
enum class FootIn2d : char { kMoving, kStill, kUnseen };

ContactWeights EstimateContacts(
    const std::vector<std::vector<double>>& points, const KinematicModel& model,
    const FitOptions& options, double fps, bool gate_by_speed,
    const std::vector<std::vector<FootIn2d>>* feet_in_2d = nullptr) {
  const int num_frames = static_cast<int>(points.size());
  const int first_sole = 3 * model.num_keypoints();
  const double max_step_m = options.contact_speed_mps / fps;
  ContactWeights contacts;
  for (int t = 0; t < num_frames; ++t) {
    const double* sole = &points[t][first_sole];
    double lowest_m = std::numeric_limits<double>::infinity();
    for (int s = 0; s < model.num_sole_points(); ++s)
      lowest_m = std::min(lowest_m, sole[3 * s + 2]);
    std::vector<double> weights;
    for (int s = 0; s < model.num_sole_points(); ++s) {
      // Above the floor (by more than the contact height) nothing holds.
      const double above_lowest_m = sole[3 * s + 2] - lowest_m;
      const bool near_floor = lowest_m < 2.0 * options.contact_height_m;
      double weight =
          near_floor && above_lowest_m < 2.0 * options.contact_height_m
              ? std::exp(-above_lowest_m / options.contact_height_m)
              : 0.0;
      const FootIn2d in_2d = feet_in_2d != nullptr
                                 ? (*feet_in_2d)[t][model.sole_foot[s]]
                                 : FootIn2d::kUnseen;
      if (gate_by_speed && in_2d != FootIn2d::kUnseen) {
        if (in_2d == FootIn2d::kMoving) weight = 0.0;
      } else if (gate_by_speed && t + 1 < num_frames) {
        const double* next = &points[t + 1][first_sole];
        const double step_m = std::hypot(next[3 * s] - sole[3 * s],
                                         next[3 * s + 1] - sole[3 * s + 1]);
        if (step_m > max_step_m) weight = 0.0;
      }
      weights.push_back(weight);
    }
    contacts.push_back(std::move(weights));
  }
  return contacts;
}

// The value below which half of the total weight lies.
double WeightedMedian(std::vector<std::pair<double, double>> value_weight) {
  std::sort(value_weight.begin(), value_weight.end());
  double total = 0.0;
  for (const auto& [value, weight] : value_weight) total += weight;
  double below = 0.0;
  for (const auto& [value, weight] : value_weight) {
    below += weight;
    if (below >= 0.5 * total) return value;
  }
  return 0.0;
}

// Where the ray through pixel `pixel_px` of frame t's camera meets the
// horizontal plane at height `plane_z_m`; false when it does not (a ray
// level or pointing up, or a point implausibly far).
bool BackProjectToPlane(const Observations& obs, const Parameters& params,
                        int t, const Eigen::Vector2d& pixel_px,
                        double plane_z_m, Eigen::Vector3d* point_m) {
  const Eigen::Matrix3d rotation =
      FitCameraRotation(params.camera.pitch_roll_rad);
  const Eigen::Vector3d ray =
      rotation.transpose() *
      Eigen::Vector3d(
          (pixel_px.x() - 0.5 * obs.width_px) / params.camera.focal_px,
          (pixel_px.y() - 0.5 * obs.height_px) / params.camera.focal_px, 1.0);
  const Eigen::Vector3d centre(params.centre(t));
  if (ray.z() > -1e-3) return false;
  const double along = (plane_z_m - centre.z()) / ray.z();
  constexpr double kMaxDistance_m = 100.0;
  if (!(along > 0) || along * ray.norm() > kMaxDistance_m) return false;
  *point_m = centre + along * ray;
  return true;
}

// For a moving camera: shifts the subject and the camera together,
// horizontally, by the travel that keeps the feet in contact in place (leg
// odometry). Only their relative motion is in the image, so this leaves
// every reprojection unchanged; it hands stage 3 the subject's travel,
// which a local solver does not find from a subject walking in place.
//
// Each foot's ankle keypoint (-1: none): of the layout's foot keypoints (a
// person's ankles), the one nearest its sole points.
std::vector<int> FootAnkles(const KinematicModel& model,
                            const KeypointLayout& layout,
                            const std::vector<std::vector<double>>& points) {
  const int num_keypoints = model.num_keypoints();
  const std::vector<int>& ankles = layout.foot_keypoints;
  std::vector<int> foot_ankle(model.num_feet, -1);
  for (int f = 0; f < model.num_feet; ++f) {
    Eigen::Vector3d sole = Eigen::Vector3d::Zero();
    int count = 0;
    for (int s = 0; s < model.num_sole_points(); ++s) {
      if (model.sole_foot[s] != f) continue;
      sole += Eigen::Map<const Eigen::Vector3d>(
          &points[0][3 * (num_keypoints + s)]);
      ++count;
    }
    if (count > 0) sole /= count;
    double nearest_m = std::numeric_limits<double>::infinity();
    for (int ankle : ankles) {
      if (ankle < 0) continue;
      const double distance_m =
          (Eigen::Map<const Eigen::Vector3d>(&points[0][3 * ankle]) - sole)
              .norm();
      if (distance_m < nearest_m) {
        nearest_m = distance_m;
        foot_ankle[f] = ankle;
      }
    }
  }
  return foot_ankle;
}

// Under a static camera, per frame and foot: whether its observed 2D ankle
// stands still, moving less over the frame (central difference) than
// options.contact_speed_mps would move it at the person's image scale
// (obs.scale_px / rest_scale_m pixels per metre). The fitted feet's own
// speed is a poor witness there: a stance foot's depth drifts in the
// estimate, and the 3D gate found 1-11 of the kick's 46 frames in contact
// (docs/fit.md, "Contacts from the 2D"). A foot whose ankle is unseen at
// either end of the difference (+-span_frames) is kUnseen: the 2D says
// nothing about it, and the callers fall back to what the 2D replaced.
std::vector<std::vector<FootIn2d>> ObservedFeet(
    const Observations& obs, const KinematicModel& model,
    const std::vector<int>& foot_ankle, double rest_scale_m,
    const FitOptions& options, int span_frames = 1) {
  std::vector<std::vector<FootIn2d>> feet(
      obs.num_frames, std::vector<FootIn2d>(model.num_feet, FootIn2d::kUnseen));
  for (int t = 0; t < obs.num_frames; ++t) {
    const double max_step_px =
        options.contact_speed_mps / obs.fps * obs.scale_px[t] / rest_scale_m;
    for (int f = 0; f < model.num_feet; ++f) {
      const int ankle = foot_ankle[f];
      if (ankle < 0) continue;
      // The widest difference whose ends are both seen: a dropped detection
      // at +-span_frames narrows it rather than hiding the foot.
      for (int span = span_frames; span >= 1; --span) {
        const int before = std::max(0, t - span);
        const int after = std::min(obs.num_frames - 1, t + span);
        if (before == after || obs.Weight(before, ankle) <= 0 ||
            obs.Weight(after, ankle) <= 0) {
          continue;
        }
        // A central difference reads the top of a jump's flight as still:
        // the ankle rises into it and falls out of it alike. Where the two
        // halves of the span move in opposite directions (a turn, which a
        // planted foot does not make), the faster half decides.
        const Eigen::Vector2d span_step =
            obs.Pixel(after, ankle) - obs.Pixel(before, ankle);
        double step_px = span_step.norm() / (after - before);
        if (span_frames > 1 && obs.Weight(t, ankle) > 0 && before < t &&
            t < after) {
          const Eigen::Vector2d rise =
              obs.Pixel(t, ankle) - obs.Pixel(before, ankle);
          const Eigen::Vector2d fall =
              obs.Pixel(after, ankle) - obs.Pixel(t, ankle);
          if (rise.dot(fall) < 0) {
            step_px =
                std::max(rise.norm() / (t - before), fall.norm() / (after - t));
          }
        }
        feet[t][f] =
            step_px < max_step_px ? FootIn2d::kStill : FootIn2d::kMoving;
        break;
      }
    }
  }
  return feet;
}

// Per frame, whether a foot can stand on the floor there: with
// ground_from_2d under a static camera, where some foot's 2D ankle is still
// over +-ground_still_span_s (ObservedFeet; the feet told apart on the rest
// pose) within +-ground_margin_s, or unseen at the frame itself (a video
// cropped above the feet keeps its floor); otherwise every frame. A jump's
// flight then pulls no sole onto the floor: held there, a camera looking
// down turned the flight into travel in depth (docs/fit.md, "Ground where a
// foot is still").
std::vector<char> GroundFrames(const Observations& obs,
                               const KinematicModel& model,
                               const KeypointLayout& layout,
                               const FitOptions& options) {
  std::vector<char> ground(obs.num_frames, 1);
  if (!options.ground_from_2d ||
      options.camera_motion != CameraMotion::kStatic) {
    return ground;
  }
  const RestPose rest = MakeRestPose(model, layout);
  const int span_frames = std::max(
      1, static_cast<int>(std::lround(options.ground_still_span_s * obs.fps)));
  const std::vector<std::vector<FootIn2d>> feet =
      ObservedFeet(obs, model, FootAnkles(model, layout, {rest.points}),
                   rest.scale_m, options, span_frames);
  const int margin_frames =
      static_cast<int>(std::lround(options.ground_margin_s * obs.fps));
  auto any_foot = [&](int t, FootIn2d what) {
    return std::count(feet[t].begin(), feet[t].end(), what) > 0;
  };
  for (int t = 0; t < obs.num_frames; ++t) {
    ground[t] = any_foot(t, FootIn2d::kUnseen);
    for (int u = std::max(0, t - margin_frames);
         u <= std::min(obs.num_frames - 1, t + margin_frames); ++u) {
      if (any_foot(u, FootIn2d::kStill)) ground[t] = 1;
    }
  }
  return ground;
}

// A foot's step is measured on its observed 2D ankle, back-projected onto
// the horizontal plane at the fitted ankle's height: the 2D and the ground
// plane fix it, where the fitted leg's depth (a front view sees a stride
// only as depth) is pulled toward rest by the pose prior. The camera's
// step at frame t is minus the weighted median, over a window of about one
// step, of the in-contact feet's steps: the stance foot moves with the
// camera for most of the window, so a foot labelled in contact while it
// lands or lifts (moving fast) is outvoted instead of averaged in.
void RemoveContactSlide(const Observations& obs, const KinematicModel& model,
                        const KeypointLayout& layout,
                        const std::vector<std::vector<double>>& points,
                        const ContactWeights& contacts, Parameters& params) {
  const int num_frames = obs.num_frames;
  const std::vector<int> foot_ankle = FootAnkles(model, layout, points);
  // Per frame pair (t, t+1): each in-contact foot's horizontal step, and
  // its weight (contact over the step times the ankles' confidence).
  struct FootStep {
    Eigen::Vector2d step_m;
    double weight;
  };
  std::vector<std::vector<FootStep>> foot_steps(num_frames);
  for (int t = 0; t + 1 < num_frames; ++t) {
    for (int f = 0; f < model.num_feet; ++f) {
      double contact = 0.0;
      for (int s = 0; s < model.num_sole_points(); ++s) {
        if (model.sole_foot[s] == f)
          contact += std::min(contacts[t][s], contacts[t + 1][s]);
      }
      const int ankle = foot_ankle[f];
      if (contact <= 0 || ankle < 0) continue;
      const double confidence =
          std::min(obs.Weight(t, ankle), obs.Weight(t + 1, ankle));
      Eigen::Vector3d before, after;
      if (confidence <= 0 ||
          !BackProjectToPlane(obs, params, t, obs.Pixel(t, ankle),
                              points[t][3 * ankle + 2], &before) ||
          !BackProjectToPlane(obs, params, t + 1, obs.Pixel(t + 1, ankle),
                              points[t + 1][3 * ankle + 2], &after)) {
        continue;
      }
      foot_steps[t].push_back(
          {(after - before).head<2>(), contact * confidence});
    }
  }
  constexpr int kHalfWindow = 16;  // frames: a gait cycle at 30 fps
  std::vector<Eigen::Vector2d> shift(num_frames, Eigen::Vector2d::Zero());
  for (int t = 0; t + 1 < num_frames; ++t) {
    std::vector<std::pair<double, double>> along_x, along_y;
    for (int k = std::max(0, t - kHalfWindow);
         k <= std::min(num_frames - 2, t + kHalfWindow); ++k) {
      for (const FootStep& foot : foot_steps[k]) {
        along_x.emplace_back(foot.step_m.x(), foot.weight);
        along_y.emplace_back(foot.step_m.y(), foot.weight);
      }
    }
    const Eigen::Vector2d step(WeightedMedian(along_x),
                               WeightedMedian(along_y));
    shift[t + 1] = shift[t] - step;
  }
  for (int t = 0; t < num_frames; ++t) {
    params.root_m[t].head<2>() += shift[t];
    params.camera.centres_m[t].head<2>() += shift[t];
    // A rig's other following cameras see the same body: they move with it.
    for (CameraParameters& camera : params.rig_cameras) {
      if (camera.centres_m.size() > 1)
        camera.centres_m[t].head<2>() += shift[t];
    }
  }
}

// The torso keypoints (shoulders and hips), which the rest pose places well
// whatever the limbs do: stage 1 fits the camera and root to them.
std::vector<double> TorsoMask(const KeypointLayout& layout) {
  std::vector<double> mask(layout.num_keypoints(), 0.0);
  for (const char* name :
       {"left_shoulder", "right_shoulder", "left_hip", "right_hip"}) {
    const int index = layout.IndexOf(name);
    if (index >= 0) mask[index] = 1.0;
  }
  return mask;
}

// Which term each residual block of a problem is, for ExplainCost. A
// FrameCost block is recorded as kReprojection and split by its residual
// layout (costs.h) when evaluated.
struct TermBlock {
  FitTerm term;
  ceres::ResidualBlockId id;
};
using TermBlocks = std::vector<TermBlock>;

// Adds a residual block of `cost` over `blocks` to `problem`, recorded as
// `term` when `term_blocks` is given.
void AddTerm(ceres::Problem& problem, TermBlocks* term_blocks, FitTerm term,
             ceres::CostFunction* cost, const std::vector<double*>& blocks) {
  const ceres::ResidualBlockId id =
      problem.AddResidualBlock(cost, nullptr, blocks);
  if (term_blocks != nullptr) term_blocks->push_back({term, id});
}

// The mean-balance terms (costs.h LeanCost), each of `weight`: the clip cut
// into windows of window_s; in each, the frames with a sole in contact
// (weight >= 0.5) get a term that moves their centre of mass's offset from
// those soles by minus the window's mean offset. A window with fewer than a
// quarter of its frames in contact (a flight) has none.
void AddMeanBalance(const KinematicModel& model, double weight, double window_s,
                    double fps, const ContactWeights& contacts,
                    Parameters& params, ceres::Problem& problem,
                    TermBlocks* term_blocks) {
  const int num_frames = static_cast<int>(params.root_m.size());
  const int window = std::max(2, static_cast<int>(std::lround(window_s * fps)));
  const auto points = FramePoints(params, model);
  const int first_sole = 3 * model.num_keypoints();
  for (int start = 0; start < num_frames; start += window) {
    std::vector<LeanCost> terms;
    std::vector<int> frames;
    Eigen::Vector2d mean_offset_m = Eigen::Vector2d::Zero();
    for (int t = start; t < std::min(num_frames, start + window); ++t) {
      LeanCost term;
      term.model = &model;
      term.weight = weight;
      Eigen::Vector2d support_m = Eigen::Vector2d::Zero();
      double total = 0.0;
      for (int k = 0; k < model.num_sole_points(); ++k) {
        const double w = contacts[t][k] >= 0.5 ? contacts[t][k] : 0.0;
        term.contact_weights.push_back(w);
        support_m += w * Eigen::Vector2d(points[t][first_sole + 3 * k],
                                         points[t][first_sole + 3 * k + 1]);
        total += w;
      }
      if (total <= 0.0) continue;
      double com_m[3];
      CenterOfMassWithJacobian(model, params.root_m[t].data(),
                               params.quaternion_wxyz[t].data(),
                               params.hinges_rad[t].data(), com_m, nullptr);
      const Eigen::Vector2d offset_m =
          Eigen::Vector2d(com_m[0], com_m[1]) - support_m / total;
      term.target_m[0] = offset_m.x();
      term.target_m[1] = offset_m.y();
      mean_offset_m += offset_m;
      terms.push_back(std::move(term));
      frames.push_back(t);
    }
    if (4 * static_cast<int>(terms.size()) < window) continue;
    mean_offset_m /= static_cast<double>(terms.size());
    for (size_t i = 0; i < terms.size(); ++i) {
      terms[i].target_m[0] -= mean_offset_m.x();
      terms[i].target_m[1] -= mean_offset_m.y();
      const int t = frames[i];
      AddTerm(problem, term_blocks, FitTerm::kMeanBalance,
              LeanCost::Create(std::move(terms[i])),
              {params.root_m[t].data(), params.quaternion_wxyz[t].data(),
               params.hinges_rad[t].data()});
    }
  }
}

// The collision-sphere pairs of frame `t` of `params` whose surfaces are
// closer than `margin_m` (overlapping ones included).
std::vector<std::pair<int, int>> NearSpherePairs(const KinematicModel& model,
                                                 const Parameters& params,
                                                 int t, double margin_m) {
  const std::vector<double> centres_m = CollisionSphereCentres(
      model, params.root_m[t].data(), params.quaternion_wxyz[t].data(),
      params.hinges_rad[t].data());
  std::vector<std::pair<int, int>> near;
  for (const auto& [a, b] : model.collision_pairs) {
    if (SphereGapM(model, centres_m, a, b) < margin_m) near.push_back({a, b});
  }
  return near;
}

// Frame t's reprojection term for `camera` (FrameCost), with the floor and
// uprightness when `with_body_terms` (once per frame, with the first
// camera); a rig's other camera (`camera.yaw_rad` a block) without.
FrameCost MakeFrameCost(const Observations& obs, const KinematicModel& model,
                        const FitOptions& options, const FitPriors& priors,
                        const std::vector<double>& keypoint_mask, int t,
                        bool with_body_terms, bool camera_yaw) {
  FrameCost cost;
  cost.model = &model;
  cost.cx_px = 0.5 * obs.width_px;
  cost.cy_px = 0.5 * obs.height_px;
  cost.inv_scale_px = 1.0 / obs.median_scale_px;
  cost.sigma = options.reprojection_sigma;
  cost.camera_yaw = camera_yaw;
  if (with_body_terms) {
    cost.ground_weight = priors.ground_frames[t] ? options.ground_weight : 0.0;
    cost.penetration_weight = options.penetration_weight;
    cost.upright_weight = options.upright_weight;
  }
  for (int j = 0; j < obs.num_keypoints; ++j) {
    cost.observed_px.push_back(obs.Pixel(t, j));
    cost.weights.push_back(obs.Weight(t, j) * keypoint_mask[j]);
  }
  return cost;
}

// Frame t's blocks of FrameCost for `camera` (its yaw last when free).
std::vector<double*> FrameBlocks(CameraParameters& camera, Parameters& params,
                                 int t, bool camera_yaw) {
  std::vector<double*> blocks = {&camera.focal_px,
                                 camera.pitch_roll_rad,
                                 camera.centre(t),
                                 params.root_m[t].data(),
                                 params.quaternion_wxyz[t].data(),
                                 params.hinges_rad[t].data()};
  if (camera_yaw) blocks.push_back(&camera.yaw_rad);
  return blocks;
}

// A camera's bounds: pitch within +-1.3 rad and roll within +-0.7 of level,
// every centre above the floor.
void BoundCamera(CameraParameters& camera, ceres::Problem& problem) {
  problem.SetParameterLowerBound(camera.pitch_roll_rad, 0, -1.3);
  problem.SetParameterUpperBound(camera.pitch_roll_rad, 0, 1.3);
  problem.SetParameterLowerBound(camera.pitch_roll_rad, 1, -0.7);
  problem.SetParameterUpperBound(camera.pitch_roll_rad, 1, 0.7);
  for (Eigen::Vector3d& centre : camera.centres_m) {
    if (problem.HasParameterBlock(centre.data()))
      problem.SetParameterLowerBound(centre.data(), 2, 0.1);
  }
}

// One camera's priors and bounds (BoundCamera): the focal fixed or free under
// its prior, pitch and roll bounded (roll under its prior when weighted), every
// centre above the floor under the height prior and, when it moves, slow and
// smooth; all held in stage 4 (refine). `defines_world`: the first centre's
// x and y are held (the world's origin is below the first camera, and its
// heading is that camera's yaw).
void AddCameraTerms(Stage stage, const FitOptions& options,
                    double focal_prior_px, bool defines_world,
                    CameraParameters& camera, ceres::Problem& problem,
                    TermBlocks* term_blocks) {
  // Focal: fixed, or free with a prior at the image diagonal.
  if (problem.HasParameterBlock(&camera.focal_px)) {
    if (options.fixed_focal_px > 0) {
      problem.SetParameterBlockConstant(&camera.focal_px);
    } else {
      AddTerm(
          problem, term_blocks, FitTerm::kFocalPrior,
          FocalPriorCost::Create(focal_prior_px, options.focal_prior_weight),
          {&camera.focal_px});
      problem.SetParameterLowerBound(&camera.focal_px, 0, 0.1 * focal_prior_px);
      problem.SetParameterUpperBound(&camera.focal_px, 0,
                                     20.0 * focal_prior_px);
    }
    // Most footage is shot level (a tripod, a person holding a phone
    // upright); without this a body's sideways lean hides in camera roll.
    if (options.camera_roll_prior_weight > 0) {
      AddTerm(
          problem, term_blocks, FitTerm::kCameraRollPrior,
          CameraRollPriorCost::Create(0.0, options.camera_roll_prior_weight),
          {camera.pitch_roll_rad});
    }
    BoundCamera(camera, problem);
    // A known tilt is the starts' and stays.
    if (options.tilt_known)
      problem.SetParameterBlockConstant(camera.pitch_roll_rad);
  }
  const int num_centres = static_cast<int>(camera.centres_m.size());
  for (int c = 0; c < num_centres; ++c) {
    double* centre = camera.centres_m[c].data();
    if (!problem.HasParameterBlock(centre)) continue;
    if (c == 0 && defines_world)
      problem.SetManifold(centre, new ceres::SubsetManifold(3, {0, 1}));
    // A person filming stands (or a tripod stands) about this high; spread
    // over a moving camera's frames so its strength does not grow with
    // the clip.
    AddTerm(problem, term_blocks, FitTerm::kCameraHeightPrior,
            CameraHeightPriorCost::Create(
                options.camera_height_prior_m,
                (num_centres > 1 ? options.moving_camera_height_prior_weight
                                 : options.camera_height_prior_weight) /
                    std::sqrt(num_centres)),
            {centre});
  }
  for (int c = 1; c < num_centres; ++c) {
    AddTerm(problem, term_blocks, FitTerm::kCameraSpeed,
            VelocityCost::Create(options.camera_speed_weight),
            {camera.centres_m[c - 1].data(), camera.centres_m[c].data()});
    if (c + 1 < num_centres) {
      AddTerm(problem, term_blocks, FitTerm::kCameraSmooth,
              AccelerationCost::Create(3, options.camera_smooth_weight),
              {camera.centres_m[c - 1].data(), camera.centres_m[c].data(),
               camera.centres_m[c + 1].data()});
    }
  }
  // Stage 4 refines the pose under the camera the search settled on: with
  // the weaker smoothness the camera would drift (docs/fit.md,
  // "Smoothness and the refinement").
  if (stage == Stage::kRefine) {
    for (double* block :
         {&camera.focal_px, camera.pitch_roll_rad, &camera.yaw_rad}) {
      if (problem.HasParameterBlock(block))
        problem.SetParameterBlockConstant(block);
    }
    for (auto& centre : camera.centres_m) {
      if (problem.HasParameterBlock(centre.data()))
        problem.SetParameterBlockConstant(centre.data());
    }
  }
}

// Adds `stage`'s terms over `params` to `problem` (docs/fit.md writes
// them out); `term_blocks` (optional) records which term each block is.
// `rig_obs`: the views of params.rig_cameras, one each (FitRig).
void BuildProblem(Stage stage, const Observations& obs,
                  const KinematicModel& model, const KeypointLayout& layout,
                  const FitOptions& options, const FitPriors& priors,
                  const ContactWeights* contacts, Parameters& params,
                  ceres::Problem& problem, TermBlocks* term_blocks = nullptr,
                  const std::vector<Observations>& rig_obs = {}) {
  const int num_frames = obs.num_frames;
  const int num_hinges = model.num_hinges();
  const std::vector<double> keypoint_mask =
      stage == Stage::kRoot ? TorsoMask(layout)
                            : std::vector<double>(obs.num_keypoints, 1.0);
  if (rig_obs.size() != params.rig_cameras.size())
    throw std::logic_error("BuildProblem: a rig camera without its view");

  // Per frame: robust reprojection of the confident keypoints (none on a
  // frame without enough), the floor, uprightness; the reprojection into
  // each of a rig's other cameras.
  for (int t = 0; t < num_frames; ++t) {
    AddTerm(problem, term_blocks, FitTerm::kReprojection,
            FrameCost::Create(MakeFrameCost(obs, model, options, priors,
                                            keypoint_mask, t, true, false)),
            FrameBlocks(params.camera, params, t, false));
    for (size_t k = 0; k < rig_obs.size(); ++k) {
      AddTerm(
          problem, term_blocks, FitTerm::kReprojection,
          FrameCost::Create(MakeFrameCost(rig_obs[k], model, options, priors,
                                          keypoint_mask, t, false, true)),
          FrameBlocks(params.rig_cameras[k], params, t, true));
    }
  }
  // Temporal smoothness of the root and of its orientation.
  for (int t = 1; t + 1 < num_frames; ++t) {
    AddTerm(problem, term_blocks, FitTerm::kRootSmooth,
            AccelerationCost::Create(3, options.root_smooth_weight),
            {params.root_m[t - 1].data(), params.root_m[t].data(),
             params.root_m[t + 1].data()});
    AddTerm(
        problem, term_blocks, FitTerm::kTurnSmooth,
        TurnAccelerationCost::Create(options.turn_smooth_weight),
        {params.quaternion_wxyz[t - 1].data(), params.quaternion_wxyz[t].data(),
         params.quaternion_wxyz[t + 1].data()});
  }
  // The pose: prior toward rest, smooth in time, within the joint ranges;
  // held at rest in stage 1.
  for (int t = 0; t < num_frames; ++t) {
    double* hinges = params.hinges_rad[t].data();
    if (stage == Stage::kRoot) {
      problem.SetParameterBlockConstant(hinges);
      continue;
    }
    if (priors.pose_mixture != nullptr) {
      AddTerm(problem, term_blocks, FitTerm::kPosePrior,
              new MixturePriorCost(priors.pose_mixture.get(),
                                   stage == Stage::kRefine
                                       ? options.refine_mixture_weight
                                   : stage == Stage::kPoseWithContacts
                                       ? options.pose_mixture_final_weight
                                       : options.pose_mixture_weight),
              {hinges});
    } else {
      AddTerm(problem, term_blocks, FitTerm::kPosePrior,
              PriorCost::Create(num_hinges, options.pose_prior_weight),
              {hinges});
    }
    if (t >= 1 && t + 1 < num_frames) {
      AddTerm(
          problem, term_blocks, FitTerm::kPoseSmooth,
          AccelerationCost::Create(
              num_hinges, stage == Stage::kRefine ? options.refine_smooth_weight
                                                  : options.pose_smooth_weight),
          {params.hinges_rad[t - 1].data(), hinges,
           params.hinges_rad[t + 1].data()});
    }
    for (int h = 0; h < num_hinges; ++h) {
      problem.SetParameterLowerBound(hinges, h, model.hinge_low_rad[h]);
      problem.SetParameterUpperBound(hinges, h, model.hinge_high_rad[h]);
    }
  }
  // Bodies that do not pass through each other: per frame, the sphere
  // pairs near enough to touch in the estimate the solve starts from. From
  // stage 3 on: in stage 2 a limb the search put on the wrong side of
  // another must be free to pass through it to the right one.
  if (HasContactTerms(stage) && options.self_contact_weight > 0) {
    for (int t = 0; t < num_frames; ++t) {
      SelfContactCost cost;
      cost.model = &model;
      cost.weight = options.self_contact_weight;
      cost.pairs =
          NearSpherePairs(model, params, t, options.self_contact_margin_m);
      if (cost.pairs.empty()) continue;
      AddTerm(problem, term_blocks, FitTerm::kSelfContact,
              SelfContactCost::Create(std::move(cost)),
              {params.root_m[t].data(), params.quaternion_wxyz[t].data(),
               params.hinges_rad[t].data()});
    }
  }
  // Feet that stay put while on the floor.
  if (HasContactTerms(stage) && contacts != nullptr) {
    for (int t = 0; t + 1 < num_frames; ++t) {
      FootSlideCost cost;
      cost.model = &model;
      bool any = false;
      for (int s = 0; s < model.num_sole_points(); ++s) {
        const double weight =
            options.foot_slide_weight *
            std::min((*contacts)[t][s], (*contacts)[t + 1][s]);
        any = any || weight > 0;
        cost.contact_weights.push_back(weight);
      }
      if (!any) continue;
      AddTerm(problem, term_blocks, FitTerm::kFootSlide,
              FootSlideCost::Create(std::move(cost)),
              {params.root_m[t].data(), params.quaternion_wxyz[t].data(),
               params.hinges_rad[t].data(), params.root_m[t + 1].data(),
               params.quaternion_wxyz[t + 1].data(),
               params.hinges_rad[t + 1].data()});
    }
  }
  // The zero-moment point over the support, where a sole is in contact.
  if (HasContactTerms(stage) && contacts != nullptr &&
      options.balance_weight > 0) {
    const int span = std::max(
        1, static_cast<int>(std::lround(options.balance_span_s * obs.fps)));
    for (int t = span; t + span < num_frames; ++t) {
      BalanceCost cost;
      cost.model = &model;
      cost.span_s = span / obs.fps;
      cost.margin_m = options.balance_margin_m;
      cost.weight = options.balance_weight;
      bool any = false;
      for (int s = 0; s < model.num_sole_points(); ++s) {
        cost.in_contact.push_back((*contacts)[t][s] >= 0.5);
        any = any || cost.in_contact.back();
      }
      if (!any) continue;
      std::vector<double*> blocks;
      for (int f : {t - span, t, t + span}) {
        blocks.insert(blocks.end(), {params.root_m[f].data(),
                                     params.quaternion_wxyz[f].data(),
                                     params.hinges_rad[f].data()});
      }
      AddTerm(problem, term_blocks, FitTerm::kBalance,
              BalanceCost::Create(std::move(cost)), blocks);
    }
  }
  // Balance on average: per window, the mean offset of the centre of mass
  // from the in-contact soles moved toward zero.
  const double mean_balance_weight =
      options.camera_motion == CameraMotion::kStatic
          ? options.mean_balance_weight
          : options.moving_camera_mean_balance_weight;
  if (HasContactTerms(stage) && contacts != nullptr &&
      mean_balance_weight > 0) {
    AddMeanBalance(model, mean_balance_weight, options.mean_balance_window_s,
                   obs.fps, *contacts, params, problem, term_blocks);
  }
  // Orientation blocks live on the unit quaternions.
  for (int t = 0; t < num_frames; ++t) {
    problem.SetManifold(params.quaternion_wxyz[t].data(),
                        new ceres::QuaternionManifold());
  }
  // The cameras.
  AddCameraTerms(stage, options, priors.focal_px, true, params.camera, problem,
                 term_blocks);
  for (size_t k = 0; k < rig_obs.size(); ++k) {
    AddCameraTerms(stage, options, FocalPriorPx(options, rig_obs[k]), false,
                   params.rig_cameras[k], problem, term_blocks);
  }
}

struct StageResult {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  double seconds = 0.0;  // wall, the solver's own account
};

// " (0.41 s)": a stage's time, for progress lines.
std::string Seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof(text), " (%.2f s)", seconds);
  return text;
}

StageResult SolveStage(Stage stage, int max_iterations, const Observations& obs,
                       const KinematicModel& model,
                       const KeypointLayout& layout, const FitOptions& options,
                       const FitPriors& priors, const ContactWeights* contacts,
                       Parameters& params,
                       const std::vector<Observations>& rig_obs = {}) {
  ceres::Problem problem;
  BuildProblem(stage, obs, model, layout, options, priors, contacts, params,
               problem, nullptr, rig_obs);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Eigen's simplicial Cholesky, not CHOLMOD's supernodal one: on systems
  // this small (a banded normal matrix of some 1,600 unknowns per 46
  // frames) CHOLMOD's OpenMP pool (4 threads, its own count) and
  // OpenBLAS's spin more than they work. Until 2026-11-23 they took 82 % of
  // a fit's CPU time; held to one OpenMP thread, its pool still cost 7-9 %
  // more CPU than wall and took the other core from a training (docs/fit.md,
  // "Speed"). Same solutions to the printed digits.
  if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE))
    solver.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  solver.max_num_iterations = max_iterations;
  solver.num_threads = options.num_threads;
  solver.function_tolerance = options.function_tolerance;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  return {summary.initial_cost, summary.final_cost,
          static_cast<int>(summary.iterations.size()),
          summary.total_time_in_seconds};
}

// Stage 1b: each limb's pose, searched frame by frame from every start of
// the limb with the trunk, root and camera held (a local solver started
// from rest does not swing a leg raised forward past the one raised back:
// both look alike in 2D and the joint limits sit between them). The best
// distinct candidates of each frame are then chained over the clip by
// dynamic programming (Viterbi), a change of the limb's hinges between
// frames costing like motion, so that a limb does not flip between its
// depth-mirrored solutions from one frame to the next.
void SearchLimbs(const Observations& obs, const KinematicModel& model,
                 const std::vector<Limb>& limbs, const FitOptions& options,
                 const FitPriors& priors, Parameters& params) {
  constexpr int kMaxCandidates = 5;
  constexpr double kDistinctRad = 0.15;  // closer candidates are one
  constexpr double kSwitchWeight = 0.3;  // per rad of change per frame
  constexpr double kMoveWeight = 0.1;    // per rad from the pose before
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.limb_search_iterations;
  solver.function_tolerance = 1e-4;
  solver.logging_type = ceres::SILENT;
  const int num_frames = obs.num_frames;
  struct Candidate {
    double cost;
    std::vector<double> values;  // the limb's hinges
  };
  for (const Limb& limb : limbs) {
    std::optional<PoseMixture> limb_mixture;
    if (priors.pose_mixture != nullptr)
      limb_mixture = priors.pose_mixture->Marginal(limb.hinges);
    std::vector<std::vector<Candidate>> candidates(num_frames);
    for (int t = 0; t < num_frames; ++t) {
      std::vector<double> current;
      for (int h : limb.hinges) current.push_back(params.hinges_rad[t][h]);
      double evidence = 0.0;
      for (int j : limb.keypoints) evidence += obs.Weight(t, j);
      if (evidence <= 0) {  // nothing seen: keep it, let the chain decide
        candidates[t].push_back({0.0, current});
        continue;
      }
      // The frame's problem: the limb's keypoints, its hinges free.
      LimbCost cost;
      cost.model = &model;
      cost.limb_hinges = limb.hinges;
      for (int j : limb.keypoints) {
        if (obs.Weight(t, j) <= 0) continue;
        cost.keypoints.push_back(j);
        cost.observed_px.push_back(obs.Pixel(t, j));
        cost.weights.push_back(obs.Weight(t, j));
      }
      cost.hinges_rad = params.hinges_rad[t];
      std::copy_n(params.root_m[t].data(), 3, cost.root_m);
      std::copy_n(params.quaternion_wxyz[t].data(), 4, cost.quaternion_wxyz);
      cost.focal_px = params.camera.focal_px;
      std::copy_n(params.camera.pitch_roll_rad, 2, cost.pitch_roll_rad);
      std::copy_n(params.centre(t), 3, cost.centre_m);
      cost.cx_px = 0.5 * obs.width_px;
      cost.cy_px = 0.5 * obs.height_px;
      cost.inv_scale_px = 1.0 / obs.median_scale_px;
      cost.sigma = options.reprojection_sigma;
      cost.penetration_weight = options.penetration_weight;
      cost.prior_weight = options.pose_prior_weight;
      if (limb_mixture.has_value()) {
        cost.limb_mixture = &*limb_mixture;
        cost.mixture_weight = options.pose_mixture_weight;
      }
      std::vector<double> angles = current;
      ceres::Problem problem;
      problem.AddResidualBlock(LimbCost::Create(std::move(cost)), nullptr,
                               angles.data());
      for (size_t i = 0; i < limb.hinges.size(); ++i) {
        problem.SetParameterLowerBound(angles.data(), i,
                                       model.hinge_low_rad[limb.hinges[i]]);
        problem.SetParameterUpperBound(angles.data(), i,
                                       model.hinge_high_rad[limb.hinges[i]]);
      }
      std::vector<Candidate> found;
      for (const std::vector<double>& start : limb.starts) {
        angles = start;
        ceres::Solver::Summary summary;
        ceres::Solve(solver, &problem, &summary);
        // A candidate pays for leaving the pose it was searched from, so a
        // depth-mirrored twin that fits the 2D no better does not win.
        double moved = 0.0;
        for (size_t i = 0; i < angles.size(); ++i) {
          const double step = kMoveWeight * (angles[i] - current[i]);
          moved += 0.5 * step * step;
        }
        found.push_back({summary.final_cost + moved, angles});
      }
      std::sort(found.begin(), found.end(),
                [](const Candidate& a, const Candidate& b) {
                  return a.cost < b.cost;
                });
      for (Candidate& candidate : found) {
        bool distinct = true;
        for (const Candidate& kept : candidates[t]) {
          double gap = 0.0;
          for (size_t i = 0; i < kept.values.size(); ++i)
            gap = std::max(gap, std::abs(kept.values[i] - candidate.values[i]));
          distinct = distinct && gap > kDistinctRad;
        }
        if (distinct) candidates[t].push_back(std::move(candidate));
        if (static_cast<int>(candidates[t].size()) == kMaxCandidates) break;
      }
    }
    // Viterbi over the frames' candidates.
    std::vector<std::vector<double>> total(num_frames);
    std::vector<std::vector<int>> from(num_frames);
    for (int t = 0; t < num_frames; ++t) {
      for (const Candidate& candidate : candidates[t]) {
        double best = 0.0;
        int best_index = -1;
        if (t > 0) {
          best = std::numeric_limits<double>::infinity();
          for (size_t c = 0; c < candidates[t - 1].size(); ++c) {
            double change = 0.0;
            for (size_t i = 0; i < candidate.values.size(); ++i) {
              const double step =
                  kSwitchWeight *
                  (candidate.values[i] - candidates[t - 1][c].values[i]);
              change += 0.5 * step * step;
            }
            if (total[t - 1][c] + change < best) {
              best = total[t - 1][c] + change;
              best_index = static_cast<int>(c);
            }
          }
        }
        total[t].push_back(best + candidate.cost);
        from[t].push_back(best_index);
      }
    }
    int chosen = static_cast<int>(
        std::min_element(total.back().begin(), total.back().end()) -
        total.back().begin());
    for (int t = num_frames - 1; t >= 0; --t) {
      const Candidate& candidate = candidates[t][chosen];
      for (size_t i = 0; i < limb.hinges.size(); ++i)
        params.hinges_rad[t][limb.hinges[i]] = candidate.values[i];
      chosen = from[t][chosen];
    }
  }
}

// Mean pixel distance of frame t's confident keypoints from their
// projection; -1 when the frame has none.
double FrameResidualPx(const Observations& obs, const KinematicModel& model,
                       const CameraParameters& camera, Parameters& params,
                       int t, double* weighted_sum, double* weight_total) {
  std::vector<double> points(3 *
                             (model.num_keypoints() + model.num_sole_points()));
  CharacterPoints(model, params.root_m[t].data(),
                  params.quaternion_wxyz[t].data(), params.hinges_rad[t].data(),
                  points.data());
  double sum = 0.0;
  int count = 0;
  for (int j = 0; j < obs.num_keypoints; ++j) {
    const double weight = obs.Weight(t, j);
    if (weight <= 0) continue;
    double pixel[2];
    FitProjectTurned(camera.focal_px, camera.pitch_roll_rad, camera.yaw_rad,
                     camera.centre(t), &points[3 * j], 0.5 * obs.width_px,
                     0.5 * obs.height_px, pixel);
    const double distance =
        (Eigen::Vector2d(pixel[0], pixel[1]) - obs.Pixel(t, j)).norm();
    sum += distance;
    ++count;
    *weighted_sum += weight * distance;
    *weight_total += weight;
  }
  return count > 0 ? sum / count : -1.0;
}

// "focal 2203 px, pitch 9.8 deg, roll 0.1 deg, height 1.62 m" (the first
// frame's centre for a moving camera), for progress lines.
std::string DescribeCamera(const Parameters& params) {
  char text[128];
  std::snprintf(
      text, sizeof(text),
      "focal %.0f px, pitch %.1f deg, roll %.1f deg, height %.2f m",
      params.camera.focal_px, params.camera.pitch_roll_rad[0] * 180.0 / M_PI,
      params.camera.pitch_roll_rad[1] * 180.0 / M_PI, params.centre(0)[2]);
  return text;
}

// The contacts of the estimate `params`, gated by the feet standing still:
// seen in the 2D (static camera, contacts_from_2d) or by the fitted feet's
// speed.
ContactWeights CurrentContacts(const Observations& obs,
                               const KinematicModel& model,
                               const KeypointLayout& layout,
                               const FitOptions& options, Parameters& params) {
  const auto points = FramePoints(params, model);
  if (options.camera_motion != CameraMotion::kStatic ||
      !options.contacts_from_2d) {
    return EstimateContacts(points, model, options, obs.fps, true);
  }
  const double rest_scale_m = MakeRestPose(model, layout).scale_m;
  const std::vector<std::vector<FootIn2d>> feet = ObservedFeet(
      obs, model, FootAnkles(model, layout, points), rest_scale_m, options);
  return EstimateContacts(points, model, options, obs.fps, true, &feet);
}

// The clip's objects in the estimate's world: each on the floor under the
// fitted cameras (RollingObjectFromPixels).
void PlaceObjects(const Clip2D& clip, const FitOptions& options,
                  const std::string& source, ViewEstimate* estimate) {
  estimate->objects.clear();
  const RollingBall ball{options.object_radius_m,
                         options.object_deceleration_m_s2};
  for (const ObjectTrack2D& track : clip.objects) {
    estimate->objects.push_back(RollingObjectFromPixels(
        track, estimate->cameras, clip.fps, ball, source));
  }
}

// The estimate of the view `obs` under `camera` (params.camera or one of
// params.rig_cameras) and its account: per-frame residuals, the frames that
// did not converge, the summary completed.
ViewEstimate ReportView(const Observations& obs, const KinematicModel& model,
                        const Character& character, const FitOptions& options,
                        const CameraParameters& camera,
                        std::chrono::steady_clock::time_point started,
                        FitSummary summary, Parameters& params) {
  ViewEstimate estimate;
  estimate.skeleton_name = model.skeleton_name;
  for (size_t c = 0; c < camera.centres_m.size(); ++c)
    estimate.cameras.push_back(camera.ToPinhole(static_cast<int>(c), obs));
  double weighted_sum = 0.0, weight_total = 0.0;
  const double unconverged_px =
      options.unconverged_residual_scale * obs.median_scale_px;
  for (int t = 0; t < obs.num_frames; ++t) {
    estimate.poses.push_back(FittedPose(character, params.root_m[t].data(),
                                        params.quaternion_wxyz[t].data(),
                                        params.hinges_rad[t].data()));
    const double residual = FrameResidualPx(obs, model, camera, params, t,
                                            &weighted_sum, &weight_total);
    estimate.residual_px.push_back(residual);
    if (!obs.usable[t] || residual > unconverged_px)
      summary.unconverged_frames.push_back(t);
  }
  summary.mean_reprojection_px =
      weight_total > 0 ? weighted_sum / weight_total : 0.0;
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started)
          .count();
  estimate.summary = summary;
  return estimate;
}

// Stages 2 to 4 from `best` over its camera and, for a rig, its other
// cameras (`rig_obs` their views); `summary` given the iterations and final
// cost.
void SolvePose(const Observations& obs, const KinematicModel& model,
               const KeypointLayout& layout, const FitOptions& options,
               const FitPriors& priors, FitSummary& summary, Parameters& best,
               const std::vector<Observations>& rig_obs = {}) {
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  // Stage 2 continues: the full pose.
  StageResult pose =
      SolveStage(Stage::kPose, options.pose_stage_iterations, obs, model,
                 layout, options, priors, nullptr, best, rig_obs);
  summary.iterations += pose.iterations;
  say("stage 2 (full pose): cost " + std::to_string(pose.initial_cost) +
      " -> " + std::to_string(pose.final_cost) + "; " + DescribeCamera(best) +
      Seconds(pose.seconds));

  // Stage 3: feet that do not slide, at the contacts the previous solve
  // found; relabelled and solved again, since better contacts move the root
  // and the root's motion sharpens the contacts.
  StageResult final_stage;
  for (int round = 0; round < options.contact_rounds; ++round) {
    if (options.camera_motion == CameraMotion::kMoving) {
      // Odometry from the height-labelled contacts, then again from
      // contacts that also stand still once the travel is in: a swing foot
      // labelled in contact moves fast then, and drops out.
      for (int pass = 0; pass < kOdometryPasses; ++pass) {
        const auto points = FramePoints(best, model);
        RemoveContactSlide(
            obs, model, layout, points,
            EstimateContacts(points, model, options, obs.fps, pass > 0), best);
      }
    }
    const ContactWeights contacts =
        CurrentContacts(obs, model, layout, options, best);
    final_stage =
        SolveStage(Stage::kPoseWithContacts, options.pose_stage_iterations, obs,
                   model, layout, options, priors, &contacts, best, rig_obs);
    summary.iterations += final_stage.iterations;
    say("stage 3 (contacts, round " + std::to_string(round + 1) + "): cost " +
        std::to_string(final_stage.initial_cost) + " -> " +
        std::to_string(final_stage.final_cost) + "; " + DescribeCamera(best) +
        Seconds(final_stage.seconds));
  }

  // Stage 4: the pose refined toward the 2D under the camera held, with
  // weaker smoothness and prior (SMPLify's falling weights, one step more).
  if (options.refine_iterations > 0) {
    const ContactWeights contacts =
        CurrentContacts(obs, model, layout, options, best);
    final_stage =
        SolveStage(Stage::kRefine, options.refine_iterations, obs, model,
                   layout, options, priors, &contacts, best, rig_obs);
    summary.iterations += final_stage.iterations;
    say("stage 4 (refine, camera held): cost " +
        std::to_string(final_stage.initial_cost) + " -> " +
        std::to_string(final_stage.final_cost) + Seconds(final_stage.seconds));
  }
  summary.final_cost = final_stage.final_cost;
}

// SolvePose, then the first camera's estimate (ReportView).
ViewEstimate SolvePoseAndReport(
    const Observations& obs, const KinematicModel& model,
    const KeypointLayout& layout, const Character& character,
    const FitOptions& options, const FitPriors& priors,
    std::chrono::steady_clock::time_point started, FitSummary& summary,
    Parameters& best, const std::vector<Observations>& rig_obs = {}) {
  SolvePose(obs, model, layout, options, priors, summary, best, rig_obs);
  return ReportView(obs, model, character, options, best.camera, started,
                    summary, best);
}

// `cameras` (1, or one per frame) and `poses` in the fit's frame (the
// camera's yaw 0, its first centre above the origin), every hinge clamped
// into its range: a start for the stages, or a state to explain. Throws
// InputError naming `source` when they do not match the frames.
Parameters GivenParameters(const Observations& obs, const KinematicModel& model,
                           const Character& character,
                           const FitOptions& options,
                           const std::vector<PinholeCamera>& cameras,
                           const std::vector<Pose3D>& poses,
                           const std::string& source) {
  if (options.tilt_known) {
    // The given camera's tilt defines the start's world.
    throw ConfigError(
        "fit: a refinement keeps its start's camera tilt (tilt_known "
        "false)");
  }
  if (static_cast<int>(poses.size()) != obs.num_frames) {
    throw InputError(source, "the start has " + std::to_string(poses.size()) +
                                 " poses for " +
                                 std::to_string(obs.num_frames) + " frames");
  }
  if (cameras.empty() || (cameras.size() != 1 &&
                          static_cast<int>(cameras.size()) != obs.num_frames)) {
    throw InputError(source, "the start has " + std::to_string(cameras.size()) +
                                 " cameras; expected 1 or one per frame");
  }
  const PinholeCamera& camera = cameras.front();
  Parameters params;
  params.camera.focal_px = options.fixed_focal_px > 0
                               ? options.fixed_focal_px
                               : camera.intrinsics().fx_px;
  const Eigen::Vector2d pitch_roll = CameraPitchRollRad(camera);
  params.camera.pitch_roll_rad[0] = pitch_roll[0];
  params.camera.pitch_roll_rad[1] = pitch_roll[1];
  // The world turned about z so that the camera looks along +x, and moved
  // so that its centre is above the origin.
  const Eigen::Matrix3d turn =
      FitCameraRotation(params.camera.pitch_roll_rad).transpose() *
      camera.rotation_world_to_camera();
  const Eigen::Vector3d centre = camera.CenterWorld();
  const Eigen::Vector3d shift(centre.x(), centre.y(), 0.0);
  // A moving camera keeps its first orientation (the fit's model).
  for (int c = 0;
       c <
       (options.camera_motion == CameraMotion::kMoving ? obs.num_frames : 1);
       ++c) {
    const PinholeCamera& at = cameras[std::min<size_t>(c, cameras.size() - 1)];
    params.camera.centres_m.push_back(turn * (at.CenterWorld() - shift));
  }
  // Along the clip: frame by frame the ball joints' Euler solutions can
  // switch (docs/fit.md, "Euler switches in the truth").
  const std::vector<std::vector<double>> rows =
      PosesToQposAlongClip(character, poses);
  const Eigen::Quaterniond turn_quaternion(turn);
  for (const std::vector<double>& qpos : rows) {
    params.root_m.push_back(
        turn * (Eigen::Vector3d(qpos[0], qpos[1], qpos[2]) - shift));
    const Eigen::Quaterniond root =
        turn_quaternion *
        Eigen::Quaterniond(qpos[3], qpos[4], qpos[5], qpos[6]);
    params.quaternion_wxyz.emplace_back(root.w(), root.x(), root.y(), root.z());
    std::vector<double> hinges(model.num_hinges());
    for (int h = 0; h < model.num_hinges(); ++h) {
      hinges[h] = std::clamp(qpos[character.hinges()[h].qpos_address],
                             model.hinge_low_rad[h], model.hinge_high_rad[h]);
    }
    params.hinges_rad.push_back(std::move(hinges));
  }
  return params;
}

// Yaws tried when placing a rig's camera against a fitted body (every
// 45 deg: a camera-only solve crosses a quarter of that).
constexpr int kRigCameraYawStarts = 8;

// A rig's camera placed against `body` (held): from each of
// kRigCameraYawStarts headings around the body's mean root, at the
// horizontal distance and height its own fit found (`alone`, that fit's
// camera; its focal held, its pitch and roll the start), the camera alone
// solved to its view `obs`; the lowest reprojection cost wins. Its own
// fit's body is not used: a depth or facing its fit got wrong would misplace
// it. A moving camera (one centre per frame in `alone`) starts on the
// body's root path, frame by frame, at that distance and heading and at its
// own fit's height of the frame, and is solved under its speed and
// smoothness terms (AddCameraTerms).
CameraParameters PlaceRigCamera(const Observations& obs,
                                const KinematicModel& model,
                                const FitOptions& options,
                                const FitPriors& priors,
                                const CameraParameters& alone,
                                double distance_m, Parameters& body,
                                int* iterations) {
  Eigen::Vector3d mean_root = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& root : body.root_m) mean_root += root;
  mean_root /= static_cast<double>(body.root_m.size());
  const std::vector<double> all_keypoints(obs.num_keypoints, 1.0);
  CameraParameters best;
  double best_cost = std::numeric_limits<double>::infinity();
  const bool moving = alone.centres_m.size() > 1;
  for (int start = 0; start < kRigCameraYawStarts; ++start) {
    CameraParameters camera = alone;
    camera.yaw_rad = 2.0 * M_PI * start / kRigCameraYawStarts;
    const Eigen::Vector2d back_m(distance_m * std::cos(camera.yaw_rad),
                                 distance_m * std::sin(camera.yaw_rad));
    for (size_t c = 0; c < camera.centres_m.size(); ++c) {
      const Eigen::Vector2d under_m =
          (moving ? body.root_m[c] : mean_root).head<2>() - back_m;
      camera.centres_m[c] =
          Eigen::Vector3d(under_m.x(), under_m.y(), alone.centres_m[c].z());
    }
    ceres::Problem problem;
    for (int t = 0; t < obs.num_frames; ++t) {
      problem.AddResidualBlock(
          FrameCost::Create(MakeFrameCost(obs, model, options, priors,
                                          all_keypoints, t, false, true)),
          nullptr, FrameBlocks(camera, body, t, true));
      for (double* block :
           {body.root_m[t].data(), body.quaternion_wxyz[t].data(),
            body.hinges_rad[t].data()}) {
        problem.SetParameterBlockConstant(block);
      }
    }
    if (moving) {
      AddCameraTerms(Stage::kPose, options, camera.focal_px, false, camera,
                     problem, nullptr);
    } else {
      BoundCamera(camera, problem);
    }
    problem.SetParameterBlockConstant(&camera.focal_px);
    ceres::Solver::Options solver;
    // 7 unknowns, or 3 per frame along a banded chain for a moving camera.
    solver.linear_solver_type =
        moving ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
    if (moving &&
        ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE))
      solver.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    solver.max_num_iterations = options.root_stage_iterations;
    solver.function_tolerance = options.function_tolerance;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    *iterations += static_cast<int>(summary.iterations.size());
    // The first start stands in when no cost compares (a NaN).
    if (start == 0 || summary.final_cost < best_cost) {
      best_cost = summary.final_cost;
      best = camera;
    }
  }
  return best;
}

// A given state (cameras and poses) read against its clip, in the fit's
// frame: what RefineView starts from and ExplainCost evaluates.
struct GivenState {
  KinematicModel model;
  Observations obs;
  Parameters params;
  FitPriors priors;

  GivenState(const Clip2D& clip, const Character& character,
             const FitOptions& options,
             const std::vector<PinholeCamera>& cameras,
             const std::vector<Pose3D>& poses, const std::string& source)
      : model(KinematicModel::FromCharacter(character)),
        obs(ReadCharacterObservations(clip, character, options, source)),
        params(GivenParameters(obs, model, character, options, cameras, poses,
                               source)),
        priors(MakeFitPriors(character, model, *clip.layout, options, obs,
                             source)) {}
};

// The cost of `blocks` in `problem`, term by term (1/2 the squared
// residuals each; FrameCost blocks split by their residual layout:
// reprojection, ground, penetration, upright; costs.h).
FitTermCosts EvaluateTerms(ceres::Problem& problem, const TermBlocks& blocks,
                           const KinematicModel& model) {
  ceres::Problem::EvaluateOptions evaluate;
  for (const TermBlock& block : blocks)
    evaluate.residual_blocks.push_back(block.id);
  double total = 0.0;
  std::vector<double> residuals;
  problem.Evaluate(evaluate, &total, &residuals, nullptr, nullptr);
  FitTermCosts costs;
  size_t at = 0;
  auto half_squares = [&](int count) {
    double sum = 0.0;
    for (int i = 0; i < count; ++i, ++at) sum += residuals[at] * residuals[at];
    return 0.5 * sum;
  };
  for (const TermBlock& block : blocks) {
    const int count =
        problem.GetCostFunctionForResidualBlock(block.id)->num_residuals();
    if (block.term != FitTerm::kReprojection) {
      costs[block.term] += half_squares(count);
      continue;
    }
    costs[FitTerm::kReprojection] += half_squares(2 * model.num_keypoints());
    costs[FitTerm::kGround] += half_squares(1);
    costs[FitTerm::kPenetration] += half_squares(model.num_sole_points());
    costs[FitTerm::kUpright] += half_squares(2);
  }
  if (at != residuals.size()) {
    throw std::logic_error(
        "EvaluateTerms: FrameCost's residual layout changed");
  }
  return costs;
}

}  // namespace

bool ParseCameraMotion(const std::string& text, CameraMotion* motion) {
  if (text == "static") {
    *motion = CameraMotion::kStatic;
  } else if (text == "moving") {
    *motion = CameraMotion::kMoving;
  } else {
    return false;
  }
  return true;
}

const char* CameraMotionName(CameraMotion motion) {
  return motion == CameraMotion::kMoving ? "moving" : "static";
}

void FitOptions::Validate() const {
  CheckRanges(*this, "fit");
  if (pitch_starts_deg.empty())
    throw ConfigError("fit.pitch_starts_deg needs at least one pitch");
}

// A clip's observations, priors and estimate (FitWholeClip).
struct ClipFit {
  Observations obs;
  FitPriors priors;
  Parameters params;
};

// Stages 1 to 4 over the whole of one view's `clip`; `summary` given the
// starts, iterations and costs.
ClipFit FitWholeClip(const Clip2D& clip, const Character& character,
                     const KinematicModel& model, const FitOptions& options,
                     const std::string& source, FitSummary& summary) {
  // Outline: read the usable observations; stage 1 fits camera and root
  // trajectory from several facing starts and keeps the lowest cost;
  // stage 1b searches each limb frame by frame; stage 2 frees the pose;
  // stage 3 adds non-sliding feet at the contacts stage 2 found; stage 4
  // refines the pose under the camera held, with weaker smoothness.
  ClipFit fit;
  fit.obs = ReadCharacterObservations(clip, character, options, source);
  const Observations& obs = fit.obs;
  const RestPose rest = MakeRestPose(model, *clip.layout);
  const std::vector<Limb> limbs = FindLimbs(model);
  fit.priors =
      MakeFitPriors(character, model, *clip.layout, options, obs, source);
  const FitPriors& priors = fit.priors;
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };

  if (options.ground_from_2d &&
      options.camera_motion == CameraMotion::kStatic) {
    const auto grounded =
        std::count(priors.ground_frames.begin(), priors.ground_frames.end(), 1);
    say("ground term in " + std::to_string(grounded) + " of " +
        std::to_string(obs.num_frames) +
        " frames (a 2D ankle still or unseen)");
  }

  summary.camera_model = CameraMotionName(options.camera_motion);
  summary.focal_fixed = options.fixed_focal_px > 0;
  summary.num_frames = obs.num_frames;
  summary.pose_prior = priors.pose_prior_name;

  // Stages 1 and 2, from each facing start: the camera and root to
  // convergence, then a short full-pose solve; the start with the lowest
  // full-pose cost continues. The torso alone hardly tells a walker seen
  // from the side facing left from one facing right (their stage 1 costs
  // tie); the legs do. Yaw pi faces the camera (which looks along +x).
  Parameters& best = fit.params;
  double best_cost = std::numeric_limits<double>::infinity();
  double best_turn_deg = 0.0;
  // A known tilt replaces the pitch starts.
  const std::vector<double> pitch_starts_deg =
      options.tilt_known ? std::vector<double>{options.known_pitch_deg}
                         : options.pitch_starts_deg;
  double best_pitch_deg = pitch_starts_deg[0];
  int num_starts_tried = 0;
  // One start: stage 1 to convergence, then the screening solve; the lowest
  // screening cost so far becomes `best`.
  auto try_start = [&](double turn_deg, double pitch_deg,
                       const std::string& name) {
    Parameters params = InitialParameters(
        obs, model, rest, options, priors.focal_px,
        M_PI + turn_deg * M_PI / 180.0, pitch_deg * M_PI / 180.0);
    const StageResult root =
        SolveStage(Stage::kRoot, options.root_stage_iterations, obs, model,
                   *clip.layout, options, priors, nullptr, params);
    const StageResult screen =
        SolveStage(Stage::kPose, options.screening_iterations, obs, model,
                   *clip.layout, options, priors, nullptr, params);
    summary.iterations += root.iterations + screen.iterations;
    if (num_starts_tried++ == 0) summary.initial_cost = root.initial_cost;
    char line[200];
    std::snprintf(line, sizeof(line),
                  "stages 1-2, %s: camera + root cost %.4g -> %.4g, full "
                  "pose %.4g (%.2f s)",
                  name.c_str(), root.initial_cost, root.final_cost,
                  screen.final_cost, root.seconds + screen.seconds);
    say(line);
    if (screen.final_cost < best_cost) {
      best = std::move(params);
      best_cost = screen.final_cost;
      best_turn_deg = turn_deg;
      best_pitch_deg = pitch_deg;
    }
  };
  for (int k = 0; k < options.num_facing_starts; ++k) {
    const double turn_deg = 360.0 * k / options.num_facing_starts;
    char name[96];
    std::snprintf(name, sizeof(name),
                  "start %d/%d (turned %.0f deg from facing the camera)", k + 1,
                  options.num_facing_starts, turn_deg);
    try_start(turn_deg, pitch_starts_deg[0], name);
  }
  // The best facing again from the other camera pitches: a camera looking
  // down on an upright body and a level one on a body leaning toward it
  // project almost alike, and a local solve from level does not cross
  // between the two.
  for (size_t p = 1; p < pitch_starts_deg.size(); ++p) {
    char name[64];
    std::snprintf(name, sizeof(name), "pitch start %zu/%zu (%.0f deg)", p + 1,
                  pitch_starts_deg.size(), pitch_starts_deg[p]);
    try_start(best_turn_deg, pitch_starts_deg[p], name);
  }
  char label[128];
  if (options.tilt_known) {
    std::snprintf(label, sizeof(label),
                  "turned %.0f deg from facing the camera, tilt known (pitch "
                  "%.1f deg, roll %.1f deg, held)",
                  best_turn_deg, options.known_pitch_deg,
                  options.known_roll_deg);
  } else {
    std::snprintf(label, sizeof(label),
                  "turned %.0f deg from facing the camera, pitch start %.0f "
                  "deg",
                  best_turn_deg, best_pitch_deg);
  }
  summary.initialization = label;

  // Stage 1b: each limb searched from a grid of starts, frame by frame.
  if (options.limb_search_iterations > 0) {
    const auto search_started = std::chrono::steady_clock::now();
    SearchLimbs(obs, model, limbs, options, priors, best);
    say("stage 1b (limb search): " + std::to_string(limbs.size()) + " limbs, " +
        std::to_string(obs.num_frames) + " frames" +
        Seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                              search_started)
                    .count()));
  }
  SolvePose(obs, model, *clip.layout, options, priors, summary, best);
  return fit;
}

// Per frame, the mean pixel distance of its confident keypoints from their
// projection (FrameResidualPx; -1: none); `mean_px` the weighted mean over
// the clip.
std::vector<double> FrameResiduals(const Observations& obs,
                                   const KinematicModel& model,
                                   Parameters& params, double* mean_px) {
  std::vector<double> residuals(obs.num_frames);
  double weighted_sum = 0.0, weight_total = 0.0;
  for (int t = 0; t < obs.num_frames; ++t) {
    residuals[t] = FrameResidualPx(obs, model, params.camera, params, t,
                                   &weighted_sum, &weight_total);
  }
  *mean_px = weight_total > 0 ? weighted_sum / weight_total : 0.0;
  return residuals;
}

// Frame `t` of `params` given `part`'s pose at its frame `u` as `part`'s
// camera sees it: the body where it stands relative to the camera, carried
// into `params`'s camera (the two fits' worlds differ in the camera's
// pitch, roll and path).
void SpliceSeenPose(const Parameters& part, int u, int t, Parameters& params) {
  const Eigen::Vector4d& q = part.quaternion_wxyz[u];
  const RootPlacement placed = CarryBetweenCameras(
      FitCameraRotation(part.camera.pitch_roll_rad, part.camera.yaw_rad),
      Eigen::Vector3d(part.camera.centre(u)),
      FitCameraRotation(params.camera.pitch_roll_rad, params.camera.yaw_rad),
      Eigen::Vector3d(params.camera.centre(t)),
      {part.root_m[u], Eigen::Quaterniond(q[0], q[1], q[2], q[3])});
  params.root_m[t] = placed.position_m;
  params.quaternion_wxyz[t] =
      Eigen::Vector4d(placed.orientation.w(), placed.orientation.x(),
                      placed.orientation.y(), placed.orientation.z());
  params.hinges_rad[t] = part.hinges_rad[u];
}

// Stage 5: the stretches the whole-clip solve left in a wrong basin, fitted
// again alone. A long clip's one start suits most of it, and the smooth
// terms hold a stretch that went wrong where it is.
void RefitStretches(const Clip2D& clip, const Character& character,
                    const KinematicModel& model, const FitOptions& options,
                    const std::string& source, FitSummary& summary,
                    ClipFit& fit) {
  // Outline: find the stretches of usable frames above the residual
  // threshold; fit each, with context on both sides, as a clip of its own
  // (stages 1-4); splice its poses, as its camera sees them, into the
  // stretch where they explain the 2D better; stages 2-4 again over the
  // whole clip from the spliced start; keep that only if the clip's mean
  // reprojection fell.
  const auto stage_started = std::chrono::steady_clock::now();
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  const Observations& obs = fit.obs;
  const double threshold_px =
      options.window_refit_residual_scale * obs.median_scale_px;
  double mean_px = 0.0;
  const std::vector<double> residuals =
      FrameResiduals(obs, model, fit.params, &mean_px);
  struct Stretch {
    int first, last;
  };
  std::vector<Stretch> stretches;
  for (int t = 0; t < obs.num_frames; ++t) {
    if (!obs.usable[t] || residuals[t] <= threshold_px) continue;
    if (!stretches.empty() && stretches.back().last == t - 1)
      stretches.back().last = t;
    else
      stretches.push_back({t, t});
  }
  if (stretches.empty()) {
    char line[120];
    std::snprintf(line, sizeof(line),
                  "stage 5 (stretches refitted): no frame above %.1f px",
                  threshold_px);
    say(line);
    return;
  }
  // Windows: each stretch with its context, overlapping ones merged.
  struct Window {
    int first, last;
    std::vector<Stretch> stretches;
  };
  std::vector<Window> windows;
  const int context = options.window_refit_context_frames;
  for (const Stretch& stretch : stretches) {
    const int first = std::max(0, stretch.first - context);
    const int last = std::min(obs.num_frames - 1, stretch.last + context);
    if (!windows.empty() && first <= windows.back().last + 1) {
      windows.back().last = last;
      windows.back().stretches.push_back(stretch);
    } else {
      windows.push_back({first, last, {stretch}});
    }
  }
  FitOptions part_options = options;
  part_options.window_refit_residual_scale = 0.0;
  part_options.progress = nullptr;
  Parameters spliced = fit.params;
  int frames_above = 0, frames_spliced = 0;
  for (size_t w = 0; w < windows.size(); ++w) {
    const Window& window = windows[w];
    const auto window_started = std::chrono::steady_clock::now();
    int window_frames_above = 0;
    for (const Stretch& stretch : window.stretches)
      window_frames_above += stretch.last - stretch.first + 1;
    frames_above += window_frames_above;
    const int count = window.last - window.first + 1;
    char line[240];
    std::snprintf(line, sizeof(line),
                  "stage 5, window %zu/%zu: frames %d-%d (%d above %.1f px)",
                  w + 1, windows.size(), window.first, window.last,
                  window_frames_above, threshold_px);
    // A window holding most of the clip is the problem already solved: its
    // own search would pick the start the whole clip's did. Stage 5 is for
    // a stretch the clip's start does not suit.
    if (2 * count > obs.num_frames) {
      say(std::string(line) + ": over half the clip, left");
      continue;
    }
    ClipFit part;
    FitSummary part_summary;
    try {
      part = FitWholeClip(ClipFrames(clip, window.first, count), character,
                          model, part_options, source, part_summary);
    } catch (const InputError& error) {
      // A window the fit cannot use alone (too few usable frames).
      say(std::string(line) + ": not fitted alone (" + error.what() + ")");
      continue;
    }
    summary.iterations += part_summary.iterations;
    double part_mean_px = 0.0;
    const std::vector<double> part_residuals =
        FrameResiduals(part.obs, model, part.params, &part_mean_px);
    double window_before = 0.0, window_after = 0.0;
    int window_spliced = 0;
    for (const Stretch& stretch : window.stretches) {
      double before = 0.0, after = 0.0;
      for (int t = stretch.first; t <= stretch.last; ++t) {
        before += std::max(0.0, residuals[t]);
        after += std::max(0.0, part_residuals[t - window.first]);
      }
      window_before += before;
      window_after += after;
      if (after >= before) continue;
      for (int t = stretch.first; t <= stretch.last; ++t)
        SpliceSeenPose(part.params, t - window.first, t, spliced);
      window_spliced += stretch.last - stretch.first + 1;
    }
    frames_spliced += window_spliced;
    char result[160];
    std::snprintf(result, sizeof(result),
                  ": %.1f px -> %.1f px fitted alone on them, %d spliced%s",
                  window_before / window_frames_above,
                  window_after / window_frames_above, window_spliced,
                  Seconds(std::chrono::duration<double>(
                              std::chrono::steady_clock::now() - window_started)
                              .count())
                      .c_str());
    say(std::string(line) + result);
  }
  char line[240];
  if (frames_spliced == 0) {
    std::snprintf(line, sizeof(line),
                  "stage 5 (stretches refitted): %d frames in %zu stretches "
                  "above %.1f px; none fitted better alone%s",
                  frames_above, stretches.size(), threshold_px,
                  Seconds(std::chrono::duration<double>(
                              std::chrono::steady_clock::now() - stage_started)
                              .count())
                      .c_str());
    say(line);
    return;
  }
  FitSummary resolved = summary;
  SolvePose(obs, model, *clip.layout, options, fit.priors, resolved, spliced);
  double spliced_mean_px = 0.0;
  const std::vector<double> spliced_residuals =
      FrameResiduals(obs, model, spliced, &spliced_mean_px);
  const bool kept = spliced_mean_px < mean_px;
  const int frames_left = static_cast<int>(
      std::count_if(spliced_residuals.begin(), spliced_residuals.end(),
                    [&](double r) { return r > threshold_px; }));
  std::snprintf(
      line, sizeof(line),
      "stage 5 (stretches refitted): %d frames in %zu stretches above %.1f "
      "px, %d spliced from their own fits; mean reprojection %.2f -> %.2f "
      "px, %d frames above (%s)%s",
      frames_above, stretches.size(), threshold_px, frames_spliced, mean_px,
      spliced_mean_px, kept ? frames_left : frames_above,
      kept ? "kept" : "not kept",
      Seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                            stage_started)
                  .count())
          .c_str());
  say(line);
  if (kept) {
    fit.params = std::move(spliced);
    summary = resolved;
  } else {
    summary.iterations = resolved.iterations;
  }
}

ViewEstimate FitView(const Clip2D& clip, const Character& character,
                     const FitOptions& options, const std::string& source) {
  // Outline: stages 1 to 4 over the whole clip (FitWholeClip); stage 5
  // fits the stretches left with high residuals again alone and splices
  // them in (RefitStretches); then report per-frame residuals and the
  // frames that did not converge, and place the clip's objects.
  options.Validate();
  const auto started = std::chrono::steady_clock::now();
  const KinematicModel model = KinematicModel::FromCharacter(character);
  FitSummary summary;
  ClipFit fit = FitWholeClip(clip, character, model, options, source, summary);
  if (options.window_refit_residual_scale > 0)
    RefitStretches(clip, character, model, options, source, summary, fit);
  ViewEstimate estimate =
      ReportView(fit.obs, model, character, options, fit.params.camera, started,
                 summary, fit.params);
  PlaceObjects(clip, options, source, &estimate);
  return estimate;
}

ViewEstimate RefineView(const Clip2D& clip, const Character& character,
                        const FitOptions& options,
                        const std::vector<PinholeCamera>& cameras,
                        const std::vector<Pose3D>& poses,
                        const std::string& source) {
  // Outline: read the observations; express the camera and poses in the
  // fit's frame, with every hinge clamped into its range; stages 2 to 4 as
  // FitView; report.
  options.Validate();
  const auto started = std::chrono::steady_clock::now();
  GivenState given(clip, character, options, cameras, poses, source);
  const KinematicModel& model = given.model;
  const Observations& obs = given.obs;
  Parameters& params = given.params;
  const FitPriors& priors = given.priors;
  FitSummary summary;
  summary.camera_model = CameraMotionName(options.camera_motion);
  summary.focal_fixed = options.fixed_focal_px > 0;
  summary.num_frames = obs.num_frames;
  summary.initialization = "the given camera and poses";
  summary.pose_prior = priors.pose_prior_name;
  // The start's cost under stage 2's objective (no iterations).
  summary.initial_cost = SolveStage(Stage::kPose, 0, obs, model, *clip.layout,
                                    options, priors, nullptr, params)
                             .initial_cost;
  ViewEstimate estimate =
      SolvePoseAndReport(obs, model, *clip.layout, character, options, priors,
                         started, summary, params);
  PlaceObjects(clip, options, source, &estimate);
  return estimate;
}

FitTermCosts ExplainCost(const Clip2D& clip, const Character& character,
                         const FitOptions& options,
                         const std::vector<PinholeCamera>& cameras,
                         const std::vector<Pose3D>& poses,
                         const std::string& source) {
  // Outline: the state in the fit's frame; its own contacts; stage 3's
  // problem over it, each block recorded with its term; evaluated, no
  // iterations.
  options.Validate();
  GivenState given(clip, character, options, cameras, poses, source);
  const KinematicModel& model = given.model;
  const Observations& obs = given.obs;
  Parameters& params = given.params;
  const FitPriors& priors = given.priors;
  const ContactWeights contacts =
      CurrentContacts(obs, model, *clip.layout, options, params);
  ceres::Problem problem;
  TermBlocks blocks;
  BuildProblem(Stage::kPoseWithContacts, obs, model, *clip.layout, options,
               priors, &contacts, params, problem, &blocks);
  return EvaluateTerms(problem, blocks, model);
}

const char* FitTermName(FitTerm term) {
  switch (term) {
    case FitTerm::kReprojection:
      return "reprojection";
    case FitTerm::kGround:
      return "ground";
    case FitTerm::kPenetration:
      return "penetration";
    case FitTerm::kUpright:
      return "upright";
    case FitTerm::kRootSmooth:
      return "root smooth";
    case FitTerm::kTurnSmooth:
      return "turn smooth";
    case FitTerm::kPosePrior:
      return "pose prior";
    case FitTerm::kPoseSmooth:
      return "pose smooth";
    case FitTerm::kFootSlide:
      return "foot slide";
    case FitTerm::kBalance:
      return "balance";
    case FitTerm::kMeanBalance:
      return "mean balance";
    case FitTerm::kFocalPrior:
      return "focal prior";
    case FitTerm::kCameraRollPrior:
      return "camera roll prior";
    case FitTerm::kCameraHeightPrior:
      return "camera height prior";
    case FitTerm::kCameraSpeed:
      return "camera speed";
    case FitTerm::kCameraSmooth:
      return "camera smooth";
    case FitTerm::kSelfContact:
      return "self contact";
  }
  return "?";
}

double FitTermCosts::Total() const {
  double total = 0.0;
  for (double c : cost) total += c;
  return total;
}

std::string FitTermCosts::BriefReport() const {
  std::string report;
  char text[64];
  for (int i = 0; i < kNumFitTerms; ++i) {
    if (cost[i] == 0.0) continue;
    std::snprintf(text, sizeof(text), "%s%s %.3g", report.empty() ? "" : ", ",
                  FitTermName(static_cast<FitTerm>(i)), cost[i]);
    report += text;
  }
  std::snprintf(text, sizeof(text), "%stotal %.3g", report.empty() ? "" : "; ",
                Total());
  return report + text;
}

ReferenceBundle FitRig(
    const ReferenceBundle& bundle, const Character& character,
    const FitOptions& options, const std::string& source,
    const std::function<void(int view, const ViewEstimate&)>& progress) {
  // Outline: fit each view alone (FitView); then, with each view's own fit
  // as the body, place every other camera against that body
  // (PlaceRigCamera) and screen a short full-pose solve over all the
  // cameras; the lowest screening cost continues through stages 2 to 4 over
  // all the cameras at once (that start's own camera defines the world);
  // report each view in that one world.
  options.Validate();
  const auto started = std::chrono::steady_clock::now();
  const int num_views = static_cast<int>(bundle.views.size());
  if (options.tilt_known) {
    throw ConfigError(
        "fit --rig: a known tilt is one camera's; a rig's cameras each "
        "have their own (tilt_known false)");
  }
  if (num_views < 2) {
    throw InputError(source,
                     "fit --rig needs 2 or more views; the bundle has " +
                         std::to_string(num_views));
  }
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  const KinematicModel model = KinematicModel::FromCharacter(character);
  const KeypointLayout& layout = *bundle.views[0].clip.layout;
  std::vector<std::string> sources;
  std::vector<Observations> obs;
  for (const ReferenceView& view : bundle.views) {
    sources.push_back(source + " (view " + view.name + ")");
    obs.push_back(ReadCharacterObservations(view.clip, character, options,
                                            sources.back()));
    if (obs.back().num_frames != obs[0].num_frames) {
      throw InputError(sources.back(),
                       std::to_string(obs.back().num_frames) +
                           " frames; a rig's views are one take (view " +
                           bundle.views[0].name + " has " +
                           std::to_string(obs[0].num_frames) + ")");
    }
  }

  // Each view alone, in its own world (the fit's frame).
  std::vector<Parameters> own;
  std::vector<double> distance_m;  // camera to the body's root, horizontal
  int iterations = 0;
  for (int v = 0; v < num_views; ++v) {
    say("view " + bundle.views[v].name + " alone:");
    const ViewEstimate alone =
        FitView(bundle.views[v].clip, character, options, sources[v]);
    iterations += alone.summary.iterations;
    own.push_back(GivenParameters(obs[v], model, character, options,
                                  alone.cameras, alone.poses, sources[v]));
    double sum = 0.0;
    for (int t = 0; t < obs[v].num_frames; ++t) {
      sum += (own.back().root_m[t] - Eigen::Vector3d(own.back().centre(t)))
                 .head<2>()
                 .norm();
    }
    distance_m.push_back(sum / obs[v].num_frames);
  }

  // The joint stages' options: a rig of moving cameras with its own
  // uprightness (FitOptions::moving_rig_upright_weight).
  FitOptions rig_options = options;
  if (options.camera_motion == CameraMotion::kMoving)
    rig_options.upright_weight = options.moving_rig_upright_weight;

  // Every view's body as the start; the others' cameras placed against it.
  // The best start keeps its state, its view's priors and the other views.
  struct RigStart {
    int view = 0;
    Parameters params;
    FitPriors priors;
    std::vector<Observations> rig_obs;
    StageResult screen;
  };
  RigStart best;
  for (int m = 0; m < num_views; ++m) {
    Parameters params = own[m];
    FitPriors priors =
        MakeFitPriors(character, model, layout, options, obs[m], sources[m]);
    std::vector<Observations> rig_obs;
    for (int k = 0; k < num_views; ++k) {
      if (k == m) continue;
      params.rig_cameras.push_back(
          PlaceRigCamera(obs[k], model, rig_options, priors, own[k].camera,
                         distance_m[k], params, &iterations));
      rig_obs.push_back(obs[k]);
    }
    const StageResult screen =
        SolveStage(Stage::kPose, options.screening_iterations, obs[m], model,
                   layout, rig_options, priors, nullptr, params, rig_obs);
    iterations += screen.iterations;
    char line[160];
    std::snprintf(line, sizeof(line),
                  "rig start %d/%d (the body of view %s): cameras placed, "
                  "full pose %.4g -> %.4g (%.2f s)",
                  m + 1, num_views, bundle.views[m].name.c_str(),
                  screen.initial_cost, screen.final_cost, screen.seconds);
    say(line);
    // The first start stands in when no cost compares (a NaN).
    if (m == 0 || screen.final_cost < best.screen.final_cost) {
      best = {m, std::move(params), std::move(priors), std::move(rig_obs),
              screen};
    }
  }

  // Stages 2 to 4 over every camera, from the best start.
  const int m = best.view;
  FitSummary summary;
  summary.camera_model = CameraMotionName(options.camera_motion);
  summary.focal_fixed = options.fixed_focal_px > 0;
  summary.num_frames = obs[m].num_frames;
  summary.pose_prior = best.priors.pose_prior_name;
  summary.initialization = "rig of " + std::to_string(num_views) +
                           " cameras, the body of view " +
                           bundle.views[m].name + "'s own fit";
  summary.iterations = iterations;
  summary.initial_cost = best.screen.initial_cost;
  std::vector<ViewEstimate> estimates(num_views);
  estimates[m] = SolvePoseAndReport(obs[m], model, layout, character,
                                    rig_options, best.priors, started, summary,
                                    best.params, best.rig_obs);
  for (int k = 0, i = 0; k < num_views; ++k) {
    if (k == m) continue;
    estimates[k] =
        ReportView(obs[k], model, character, options,
                   best.params.rig_cameras[i++], started, summary, best.params);
  }
  for (int v = 0; v < num_views; ++v) {
    PlaceObjects(bundle.views[v].clip, options, sources[v], &estimates[v]);
    if (progress) progress(v, estimates[v]);
  }
  ReferenceBundle out = bundle;
  out.estimate = std::move(estimates);
  out.estimate_one_world = true;
  return out;
}

ReferenceBundle FitBundle(
    const ReferenceBundle& bundle, const Character& character,
    const FitOptions& options, const std::string& source,
    const std::function<void(int view, const ViewEstimate&)>& progress) {
  ReferenceBundle out = bundle;
  std::vector<ViewEstimate> estimates;
  for (size_t v = 0; v < bundle.views.size(); ++v) {
    estimates.push_back(
        FitView(bundle.views[v].clip, character, options,
                source + " (view " + bundle.views[v].name + ")"));
    if (progress) progress(static_cast<int>(v), estimates.back());
  }
  out.estimate = std::move(estimates);
  out.estimate_one_world = false;
  return out;
}

}  // namespace m2d
