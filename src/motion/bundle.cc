#include "motion/bundle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "camera/camera_io.h"
#include "common/error.h"
#include "common/file_io.h"
#include "common/json_fields.h"
#include "motion/clip_io.h"

namespace m2d {
namespace {

nlohmann::json Vector3ToJson(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

Eigen::Vector3d Vector3FromJson(const JsonCursor& cursor) {
  cursor.ArraySize(3);
  return {cursor.At(0).Number(), cursor.At(1).Number(), cursor.At(2).Number()};
}

// Poses as root_position_m + local_rotations_wxyz (ground truth and
// estimate share the form).
nlohmann::json PosesToJson(const std::vector<Pose3D>& poses) {
  nlohmann::json json = nlohmann::json::array();
  for (const Pose3D& pose : poses) {
    nlohmann::json rotations = nlohmann::json::array();
    for (const Eigen::Quaterniond& q : pose.local_rotations) {
      rotations.push_back({q.w(), q.x(), q.y(), q.z()});
    }
    json.push_back({{"root_position_m", Vector3ToJson(pose.root_position_m)},
                    {"local_rotations_wxyz", rotations}});
  }
  return json;
}

std::vector<Pose3D> PosesFromJson(const JsonCursor& poses, long num_frames) {
  std::vector<Pose3D> out;
  size_t count = poses.ArraySize(num_frames);
  size_t num_joints = 0;
  for (size_t t = 0; t < count; ++t) {
    JsonCursor entry = poses.At(t);
    Pose3D pose;
    pose.root_position_m = Vector3FromJson(entry.Field("root_position_m"));
    JsonCursor rotations = entry.Field("local_rotations_wxyz");
    size_t joints =
        rotations.ArraySize(t == 0 ? -1 : static_cast<long>(num_joints));
    num_joints = joints;
    for (size_t j = 0; j < joints; ++j) {
      JsonCursor q = rotations.At(j);
      q.ArraySize(4);
      Eigen::Quaterniond rotation(q.At(0).Number(), q.At(1).Number(),
                                  q.At(2).Number(), q.At(3).Number());
      if (std::abs(rotation.norm() - 1.0) > 1e-3)
        q.Fail("not a unit quaternion");
      pose.local_rotations.push_back(rotation.normalized());
    }
    out.push_back(pose);
  }
  return out;
}

// Objects as [{name, positions_m: T x 3}] (ground truth and estimate share
// the form).
nlohmann::json ObjectsToJson(const std::vector<ObjectTrack3D>& objects) {
  nlohmann::json json = nlohmann::json::array();
  for (const ObjectTrack3D& object : objects) {
    nlohmann::json positions = nlohmann::json::array();
    for (const Eigen::Vector3d& p : object.positions_m)
      positions.push_back(Vector3ToJson(p));
    json.push_back({{"name", object.name}, {"positions_m", positions}});
  }
  return json;
}

std::vector<ObjectTrack3D> ObjectsFromJson(const JsonCursor& cursor) {
  std::vector<ObjectTrack3D> objects;
  const size_t count = cursor.ArraySize();
  for (size_t i = 0; i < count; ++i) {
    JsonCursor entry = cursor.At(i);
    ObjectTrack3D object;
    object.name = entry.Field("name").String();
    JsonCursor positions = entry.Field("positions_m");
    const size_t num_frames = positions.ArraySize();
    for (size_t t = 0; t < num_frames; ++t)
      object.positions_m.push_back(Vector3FromJson(positions.At(t)));
    objects.push_back(std::move(object));
  }
  return objects;
}

nlohmann::json GroundTruthToJson(const GroundTruth3D& truth) {
  nlohmann::json keypoints = nlohmann::json::array();
  for (const auto& frame : truth.keypoints_m) {
    nlohmann::json points = nlohmann::json::array();
    for (const Eigen::Vector3d& p : frame) points.push_back(Vector3ToJson(p));
    keypoints.push_back(points);
  }
  nlohmann::json json = {{"layout", truth.layout->name},
                         {"keypoints_m", keypoints}};
  if (!truth.poses.empty()) {
    json["skeleton"] = truth.skeleton_name;
    json["poses"] = PosesToJson(truth.poses);
  }
  if (!truth.objects.empty()) json["objects"] = ObjectsToJson(truth.objects);
  return json;
}

GroundTruth3D GroundTruthFromJson(const JsonCursor& cursor) {
  GroundTruth3D truth;
  std::string layout = cursor.Field("layout").String();
  truth.layout = FindLayout(layout);
  if (truth.layout == nullptr)
    cursor.Field("layout").Fail("unknown layout '" + layout + "'");
  JsonCursor frames = cursor.Field("keypoints_m");
  size_t num_frames = frames.ArraySize();
  for (size_t t = 0; t < num_frames; ++t) {
    JsonCursor frame = frames.At(t);
    frame.ArraySize(truth.layout->num_keypoints());
    std::vector<Eigen::Vector3d> points;
    for (int j = 0; j < truth.layout->num_keypoints(); ++j) {
      points.push_back(Vector3FromJson(frame.At(j)));
    }
    truth.keypoints_m.push_back(points);
  }
  if (cursor.Has("poses")) {
    truth.skeleton_name = cursor.Field("skeleton").String();
    truth.poses =
        PosesFromJson(cursor.Field("poses"), static_cast<long>(num_frames));
  }
  if (cursor.Has("objects"))
    truth.objects = ObjectsFromJson(cursor.Field("objects"));
  return truth;
}

nlohmann::json SummaryToJson(const FitSummary& summary) {
  return {{"camera_model", summary.camera_model},
          {"focal_fixed", summary.focal_fixed},
          {"initialization", summary.initialization},
          {"pose_prior", summary.pose_prior},
          {"num_frames", summary.num_frames},
          {"iterations", summary.iterations},
          {"initial_cost", summary.initial_cost},
          {"final_cost", summary.final_cost},
          {"mean_reprojection_px", summary.mean_reprojection_px},
          {"unconverged_frames", summary.unconverged_frames},
          {"seconds", summary.seconds}};
}

FitSummary SummaryFromJson(const JsonCursor& cursor) {
  FitSummary summary;
  summary.camera_model = cursor.Field("camera_model").String();
  summary.focal_fixed = cursor.Field("focal_fixed").Boolean();
  summary.initialization = cursor.Field("initialization").String();
  // Bundles fitted before the learned prior (format 3) lack it.
  if (cursor.Has("pose_prior"))
    summary.pose_prior = cursor.Field("pose_prior").String();
  summary.num_frames = static_cast<int>(cursor.Field("num_frames").Integer());
  summary.iterations = static_cast<int>(cursor.Field("iterations").Integer());
  summary.initial_cost = cursor.Field("initial_cost").Number();
  summary.final_cost = cursor.Field("final_cost").Number();
  summary.mean_reprojection_px = cursor.Field("mean_reprojection_px").Number();
  JsonCursor frames = cursor.Field("unconverged_frames");
  const size_t count = frames.ArraySize();
  for (size_t i = 0; i < count; ++i)
    summary.unconverged_frames.push_back(
        static_cast<int>(frames.At(i).Integer()));
  summary.seconds = cursor.Field("seconds").Number();
  return summary;
}

nlohmann::json EstimateToJson(const std::vector<ViewEstimate>& estimate,
                              const std::vector<ReferenceView>& views) {
  nlohmann::json entries = nlohmann::json::array();
  for (size_t k = 0; k < estimate.size(); ++k) {
    const ViewEstimate& view = estimate[k];
    nlohmann::json cameras = nlohmann::json::array();
    for (const PinholeCamera& camera : view.cameras)
      cameras.push_back(CameraToJson(camera));
    entries.push_back({{"name", views[k].name},
                       {"cameras", cameras},
                       {"skeleton", view.skeleton_name},
                       {"poses", PosesToJson(view.poses)},
                       {"residual_px", view.residual_px},
                       {"summary", SummaryToJson(view.summary)}});
    if (!view.objects.empty())
      entries.back()["objects"] = ObjectsToJson(view.objects);
  }
  return {{"views", entries}};
}

// The estimate section; its views must be the bundle's, in order.
std::vector<ViewEstimate> EstimateFromJson(
    const JsonCursor& cursor, const std::vector<ReferenceView>& views) {
  JsonCursor entries = cursor.Field("views");
  const size_t count = entries.ArraySize(static_cast<long>(views.size()));
  std::vector<ViewEstimate> estimate;
  for (size_t k = 0; k < count; ++k) {
    JsonCursor entry = entries.At(k);
    const std::string name = entry.Field("name").String();
    if (name != views[k].name) {
      entry.Field("name").Fail("estimate of view '" + name + "' where view '" +
                               views[k].name +
                               "' was expected (one per view, in order)");
    }
    ViewEstimate view;
    JsonCursor cameras = entry.Field("cameras");
    const size_t num_cameras = cameras.ArraySize();
    for (size_t i = 0; i < num_cameras; ++i)
      view.cameras.push_back(CameraFromJson(cameras.At(i)));
    view.skeleton_name = entry.Field("skeleton").String();
    view.poses = PosesFromJson(entry.Field("poses"), -1);
    JsonCursor residuals = entry.Field("residual_px");
    const size_t num_residuals = residuals.ArraySize();
    for (size_t t = 0; t < num_residuals; ++t)
      view.residual_px.push_back(residuals.At(t).Number());
    view.summary = SummaryFromJson(entry.Field("summary"));
    if (entry.Has("objects"))
      view.objects = ObjectsFromJson(entry.Field("objects"));
    estimate.push_back(std::move(view));
  }
  return estimate;
}

bool PoseIsFinite(const Pose3D& pose) {
  if (!pose.root_position_m.allFinite()) return false;
  for (const Eigen::Quaterniond& q : pose.local_rotations) {
    if (!q.coeffs().allFinite()) return false;
  }
  return true;
}

// 3D object tracks (`where`: "ground truth" or a view's estimate) each name
// one of `clip`'s 2D objects, once, with `num_frames` finite positions.
void ValidateObjects(const std::vector<ObjectTrack3D>& objects,
                     const Clip2D& clip, int num_frames,
                     const std::string& source, const std::string& where) {
  for (size_t i = 0; i < objects.size(); ++i) {
    const ObjectTrack3D& object = objects[i];
    const std::string what = where + " object '" + object.name + "'";
    bool tracked = false;
    for (const ObjectTrack2D& track : clip.objects)
      tracked = tracked || track.name == object.name;
    if (!tracked)
      throw InputError(source, what + " has no 2D track in the clips");
    if (FindObjectTrack(objects, object.name) != &object)
      throw InputError(source, what + " appears twice");
    if (static_cast<int>(object.positions_m.size()) != num_frames) {
      throw InputError(source, what + " has " +
                                   std::to_string(object.positions_m.size()) +
                                   " positions, clips have " +
                                   std::to_string(num_frames) + " frames");
    }
    for (int t = 0; t < num_frames; ++t) {
      if (!object.positions_m[t].allFinite()) {
        throw InputError(
            source, what + ": frame " + std::to_string(t) + " is not finite");
      }
    }
  }
}

// `point_m` as a detector reports it in `camera`'s image: projected
// (confidence 0 behind the camera), then corrupted by `noise`.
void ProjectAsDetected(const PinholeCamera& camera,
                       const Eigen::Vector3d& point_m,
                       const DetectorNoiseOptions& noise, std::mt19937_64& rng,
                       std::normal_distribution<double>& unit_normal,
                       std::uniform_real_distribution<double>& unit_uniform,
                       Keypoint2D* keypoint) {
  const Projection projection = camera.Project(point_m);
  keypoint->x_px = projection.pixel_px.x();
  keypoint->y_px = projection.pixel_px.y();
  keypoint->confidence = projection.in_front ? 1.0 : 0.0;
  CorruptKeypoint(noise.pixel_sigma_px, noise.drop_probability, rng,
                  unit_normal, unit_uniform, keypoint);
}

}  // namespace

const ObjectTrack3D* FindObjectTrack(const std::vector<ObjectTrack3D>& tracks,
                                     const std::string& name) {
  for (const ObjectTrack3D& track : tracks) {
    if (track.name == name) return &track;
  }
  return nullptr;
}

void ValidateBundle(const ReferenceBundle& bundle, const std::string& source) {
  if (bundle.views.empty()) throw InputError(source, "bundle has no views");
  if (!(bundle.fps >= kMinClipFps && bundle.fps <= kMaxClipFps)) {
    throw InputError(source, "fps " + std::to_string(bundle.fps) +
                                 " is outside [" + std::to_string(kMinClipFps) +
                                 ", " + std::to_string(kMaxClipFps) + "]");
  }
  const int num_frames = bundle.num_frames();
  for (const ReferenceView& view : bundle.views) {
    ValidateClip(view.clip, source + " (view " + view.name + ")");
    if (view.clip.num_frames() != num_frames) {
      throw InputError(source, "view " + view.name + " has " +
                                   std::to_string(view.clip.num_frames()) +
                                   " frames, the first view has " +
                                   std::to_string(num_frames));
    }
    if (std::abs(view.clip.fps - bundle.fps) > 1e-9) {
      throw InputError(source,
                       "view " + view.name + " fps differs from the bundle's");
    }
    // No cameras: unknown (stripped, or a user's video).
    if (!view.cameras.empty() && view.cameras.size() != 1 &&
        static_cast<int>(view.cameras.size()) != num_frames) {
      throw InputError(source, "view " + view.name + " has " +
                                   std::to_string(view.cameras.size()) +
                                   " cameras: need none, 1 or one per frame (" +
                                   std::to_string(num_frames) + ")");
    }
  }
  if (bundle.estimate) {
    const std::vector<ViewEstimate>& estimate = *bundle.estimate;
    if (estimate.size() != bundle.views.size()) {
      throw InputError(source, "estimate has " +
                                   std::to_string(estimate.size()) +
                                   " views, the bundle has " +
                                   std::to_string(bundle.views.size()));
    }
    for (size_t k = 0; k < estimate.size(); ++k) {
      const ViewEstimate& view = estimate[k];
      const std::string where = "estimate of view " + bundle.views[k].name;
      auto count_error = [&](const std::string& what, size_t count,
                             const std::string& need) {
        return InputError(source, where + " has " + std::to_string(count) +
                                      " " + what + ": need " + need + " (" +
                                      std::to_string(num_frames) + " frames)");
      };
      if (view.cameras.size() != 1 &&
          static_cast<int>(view.cameras.size()) != num_frames) {
        throw count_error("cameras", view.cameras.size(), "1 or one per frame");
      }
      if (static_cast<int>(view.poses.size()) != num_frames)
        throw count_error("poses", view.poses.size(), "one per frame");
      if (static_cast<int>(view.residual_px.size()) != num_frames) {
        throw count_error("residuals", view.residual_px.size(),
                          "one per frame");
      }
      for (int t = 0; t < num_frames; ++t) {
        if (!PoseIsFinite(view.poses[t]) ||
            !std::isfinite(view.residual_px[t])) {
          throw InputError(source, where + ": frame " + std::to_string(t) +
                                       " has a non-finite pose or residual");
        }
      }
      for (const PinholeCamera& camera : view.cameras) {
        const Intrinsics& k = camera.intrinsics();
        if (!camera.rotation_world_to_camera().allFinite() ||
            !camera.translation_m().allFinite() || !std::isfinite(k.fx_px) ||
            !std::isfinite(k.fy_px) || !std::isfinite(k.cx_px) ||
            !std::isfinite(k.cy_px)) {
          throw InputError(source, where + ": a camera is not finite");
        }
      }
      ValidateObjects(view.objects, bundle.views[k].clip, num_frames, source,
                      where);
      const FitSummary& summary = view.summary;
      if (!std::isfinite(summary.initial_cost) ||
          !std::isfinite(summary.final_cost) ||
          !std::isfinite(summary.mean_reprojection_px) ||
          !std::isfinite(summary.seconds)) {
        throw InputError(source, where + ": the fit summary is not finite");
      }
    }
  }
  if (bundle.ground_truth) {
    const GroundTruth3D& truth = *bundle.ground_truth;
    if (static_cast<int>(truth.keypoints_m.size()) != num_frames) {
      throw InputError(source, "ground truth has " +
                                   std::to_string(truth.keypoints_m.size()) +
                                   " frames, clips have " +
                                   std::to_string(num_frames));
    }
    if (!truth.poses.empty() &&
        static_cast<int>(truth.poses.size()) != num_frames) {
      throw InputError(source,
                       "ground-truth poses do not match the frame count");
    }
    ValidateObjects(truth.objects, bundle.views.front().clip, num_frames,
                    source, "ground truth");
  }
}

ReferenceBundle ReadBundleOrClip(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  if (!json.is_object() || json.value("format", "") != kClipFormat)
    return ReadBundle(path);
  ReferenceBundle bundle;
  bundle.name = std::filesystem::path(path).stem().string();
  ReferenceView view;
  view.name = "view0";
  view.clip = ClipFromJson(JsonCursor(json, path));  // parsed once
  bundle.fps = view.clip.fps;
  bundle.views.push_back(std::move(view));
  ValidateBundle(bundle, path);
  return bundle;
}

ReferenceBundle ReadBundle(const std::string& path) {
  nlohmann::json json = ReadJsonFile(path);
  JsonCursor root(json, path);
  if (root.Field("format").String() != kBundleFormat) {
    root.Field("format").Fail(std::string("expected \"") + kBundleFormat +
                              "\"");
  }
  // Version 1 (no estimate, cameras always known) reads as it is.
  const long version = root.Field("version").Integer();
  if (version != 1 && version != kBundleVersion) {
    root.Field("version").Fail("unsupported version " +
                               std::to_string(version) + " (reads 1 and " +
                               std::to_string(kBundleVersion) + ")");
  }
  ReferenceBundle bundle;
  bundle.name = root.Field("name").String();
  bundle.fps = root.Field("fps").Number();
  JsonCursor views = root.Field("views");
  size_t num_views = views.ArraySize();
  for (size_t k = 0; k < num_views; ++k) {
    JsonCursor entry = views.At(k);
    ReferenceView view;
    view.name = entry.Field("name").String();
    JsonCursor cameras = entry.Field("cameras");
    size_t num_cameras = cameras.ArraySize();
    for (size_t i = 0; i < num_cameras; ++i) {
      view.cameras.push_back(CameraFromJson(cameras.At(i)));
    }
    view.clip = ClipFromJson(entry.Field("clip"));
    bundle.views.push_back(std::move(view));
  }
  if (root.Has("ground_truth")) {
    bundle.ground_truth = GroundTruthFromJson(root.Field("ground_truth"));
  }
  if (version >= 2 && root.Has("estimate")) {
    const JsonCursor estimate = root.Field("estimate");
    bundle.estimate = EstimateFromJson(estimate, bundle.views);
    bundle.estimate_one_world =
        estimate.Has("one_world") && estimate.Field("one_world").Boolean();
  }
  ValidateBundle(bundle, path);
  return bundle;
}

void WriteBundle(const std::string& path, const ReferenceBundle& bundle) {
  ValidateBundle(bundle, path);
  nlohmann::json views = nlohmann::json::array();
  for (const ReferenceView& view : bundle.views) {
    nlohmann::json cameras = nlohmann::json::array();
    for (const PinholeCamera& camera : view.cameras) {
      cameras.push_back(CameraToJson(camera));
    }
    views.push_back({{"name", view.name},
                     {"cameras", cameras},
                     {"clip", ClipToJson(view.clip)}});
  }
  nlohmann::json json = {{"format", kBundleFormat},
                         {"version", kBundleVersion},
                         {"name", bundle.name},
                         {"fps", bundle.fps},
                         {"views", views}};
  if (bundle.ground_truth)
    json["ground_truth"] = GroundTruthToJson(*bundle.ground_truth);
  if (bundle.estimate) {
    json["estimate"] = EstimateToJson(*bundle.estimate, bundle.views);
    if (bundle.estimate_one_world) json["estimate"]["one_world"] = true;
  }
  WriteJsonFileAtomic(path, json);
}

ReferenceBundle StripBundle(ReferenceBundle bundle) {
  bundle.ground_truth.reset();
  bundle.estimate.reset();
  bundle.estimate_one_world = false;
  for (ReferenceView& view : bundle.views) view.cameras.clear();
  return bundle;
}

bool FitSummary::Unreliable() const {
  return static_cast<double>(unconverged_frames.size()) >
         kMaxUnconvergedFraction * num_frames;
}

std::string FitSummary::BriefReport() const {
  // Outline: the model and start, the solve, the fit quality, the frames
  // that failed (first few).
  char line[256];
  std::string report;
  std::snprintf(
      line, sizeof(line), "camera %s, focal %s, initialization %s, %d frames\n",
      camera_model.c_str(), focal_fixed ? "fixed" : "estimated",
      initialization.empty() ? "-" : initialization.c_str(), num_frames);
  report += line;
  if (!pose_prior.empty()) report += "pose prior: " + pose_prior + "\n";
  std::snprintf(line, sizeof(line),
                "%d iterations, cost %.6g -> %.6g, mean reprojection %.2f px, "
                "%.1f s\n",
                iterations, initial_cost, final_cost, mean_reprojection_px,
                seconds);
  report += line;
  if (converged()) {
    report += "all frames converged\n";
  } else {
    constexpr size_t kListed = 10;
    report +=
        std::to_string(unconverged_frames.size()) + " frames did not converge:";
    for (size_t i = 0; i < unconverged_frames.size() && i < kListed; ++i)
      report += " " + std::to_string(unconverged_frames[i]);
    if (unconverged_frames.size() > kListed) report += " ...";
    report += "\n";
  }
  return report;
}

void DetectorNoiseOptions::Validate() const {
  if (!(pixel_sigma_px >= 0))
    throw ConfigError("noise: pixel_sigma_px must be >= 0");
  if (!(drop_probability >= 0 && drop_probability < 1)) {
    throw ConfigError("noise: drop_probability must be in [0, 1)");
  }
  if (!(time_jitter_frames >= 0)) {
    throw ConfigError("noise: time_jitter_frames must be >= 0");
  }
}

void BundleFromMotionOptions::Validate() const {
  if (!(fps > 0 && fps <= 1000))
    throw ConfigError("bundle: fps must be in (0, 1000]");
  if (!(duration_s >= 0)) throw ConfigError("bundle: duration_s must be >= 0");
  if (!(follow_smoothing_s >= 0)) {
    throw ConfigError("bundle: follow_smoothing_s must be >= 0");
  }
  rig.Validate();
  noise.Validate();
}

namespace {

// Keypoints of every frame at a fractional frame index (linear blend).
std::vector<Eigen::Vector3d> BlendFrames(
    const std::vector<std::vector<Eigen::Vector3d>>& frames, double index) {
  double clamped =
      std::clamp(index, 0.0, static_cast<double>(frames.size() - 1));
  size_t lower = static_cast<size_t>(std::floor(clamped));
  size_t upper = std::min(lower + 1, frames.size() - 1);
  double alpha = clamped - lower;
  std::vector<Eigen::Vector3d> out(frames[lower].size());
  for (size_t j = 0; j < out.size(); ++j) {
    out[j] = (1 - alpha) * frames[lower][j] + alpha * frames[upper][j];
  }
  return out;
}

// The subject's ground path (root x, y), averaged over a centred window.
std::vector<Eigen::Vector3d> SmoothedGroundPath(
    const std::vector<Pose3D>& poses, int half_window) {
  std::vector<Eigen::Vector3d> path(poses.size());
  const int count = static_cast<int>(poses.size());
  for (int t = 0; t < count; ++t) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int used = 0;
    // Centred: near the ends the window shrinks on both sides, so a subject
    // moving steadily is followed at its own pace. A window cut on one side
    // only lags and then stalls (a 0.8-s run under a 1-s window: half speed,
    // a stop, half speed), which no camera operator does.
    const int half = std::min({half_window, t, count - 1 - t});
    for (int s = t - half; s <= t + half; ++s, ++used) {
      sum += poses[s].root_position_m;
    }
    path[t] = sum / used;
    path[t].z() = 0.0;
  }
  return path;
}

}  // namespace

Motion3D SampleMotionForBundle(const Motion3D& motion,
                               const BundleFromMotionOptions& options) {
  options.Validate();
  Motion3D sampled =
      ExtendLoop(motion, options.duration_s, options.loop_heading);
  sampled = ResampleMotion(sampled, options.fps);
  if (options.duration_s > 0) {
    int wanted =
        static_cast<int>(std::floor(options.duration_s * options.fps + 1e-9)) +
        1;
    if (wanted < sampled.num_frames()) sampled.frames.resize(wanted);
  }
  return sampled;
}

ReferenceBundle MakeBundleFromMotion(
    const Motion3D& motion, const KeypointMap& keypoint_map,
    const BundleFromMotionOptions& options, const std::string& name,
    const std::vector<ObjectTrack3D>& objects) {
  // Outline: loop/resample the motion to the clip rate, run FK for the 3D
  // keypoints, place the rig at the start root (or the path's middle), project
  // per view (moving the camera with the subject when following), add detector
  // noise; the same for the objects' centres.
  const Motion3D sampled = SampleMotionForBundle(motion, options);
  if (sampled.num_frames() < 1) throw InputError(name, "motion has no frames");
  for (const ObjectTrack3D& object : objects) {
    if (static_cast<int>(object.positions_m.size()) != sampled.num_frames()) {
      throw InputError(name, "object '" + object.name + "' has " +
                                 std::to_string(object.positions_m.size()) +
                                 " positions for " +
                                 std::to_string(sampled.num_frames()) +
                                 " frames");
    }
  }

  ReferenceBundle bundle;
  bundle.name = name;
  bundle.fps = options.fps;
  GroundTruth3D truth;
  truth.layout = keypoint_map.layout;
  truth.skeleton_name = motion.skeleton->name;
  for (const Pose3D& pose : sampled.frames) {
    truth.keypoints_m.push_back(
        KeypointPositions(*motion.skeleton, keypoint_map, pose));
  }
  truth.poses = sampled.frames;
  truth.objects = objects;

  RigOptions rig = options.rig;
  Eigen::Vector3d aim = sampled.frames.front().root_position_m;
  if (options.aim == RigAim::kPathMiddle) {
    aim = 0.5 * (aim + sampled.frames.back().root_position_m);
  }
  rig.target_m += Eigen::Vector3d(aim.x(), aim.y(), 0.0);
  std::vector<NamedCamera> base_cameras = MakeRig(rig);
  std::vector<Eigen::Vector3d> path;
  if (options.follow == CameraFollow::kRootDolly) {
    int half_window = static_cast<int>(
        std::round(0.5 * options.follow_smoothing_s * options.fps));
    path = SmoothedGroundPath(sampled.frames, half_window);
  }

  std::mt19937_64 rng(options.noise.seed);
  std::mt19937_64 object_rng(options.noise.seed + 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit_uniform(0.0, 1.0);
  const int num_frames = sampled.num_frames();
  const int num_keypoints = keypoint_map.layout->num_keypoints();
  for (const NamedCamera& base : base_cameras) {
    ReferenceView view;
    view.name = base.name;
    if (path.empty()) {
      view.cameras = {base.camera};
    } else {
      for (int t = 0; t < num_frames; ++t) {
        view.cameras.push_back(base.camera.Translated(path[t] - path[0]));
      }
    }
    view.clip.layout = keypoint_map.layout;
    view.clip.fps = options.fps;
    view.clip.image_width_px = rig.width_px;
    view.clip.image_height_px = rig.height_px;
    view.clip.keypoints = KeypointTrack(num_frames, num_keypoints);
    for (int t = 0; t < num_frames; ++t) {
      const PinholeCamera& camera = view.CameraAt(t);
      std::vector<Eigen::Vector3d> points =
          options.noise.time_jitter_frames > 0
              ? BlendFrames(
                    truth.keypoints_m,
                    t + options.noise.time_jitter_frames * unit_normal(rng))
              : truth.keypoints_m[t];
      for (int j = 0; j < num_keypoints; ++j) {
        ProjectAsDetected(camera, points[j], options.noise, rng, unit_normal,
                          unit_uniform, &view.clip.keypoints.at(t, j));
      }
    }
    // The objects' 2D, with noise from their own stream, so that the
    // keypoints draw the same noise with or without objects. A ball outside
    // the image is not detected (confidence 0), as a detector would miss
    // it; a kicked ball leaves the frame where the person does not.
    for (const ObjectTrack3D& object : objects) {
      ObjectTrack2D track;
      track.name = object.name;
      track.points.resize(num_frames);
      for (int t = 0; t < num_frames; ++t) {
        Keypoint2D& point = track.points[t];
        ProjectAsDetected(view.CameraAt(t), object.positions_m[t],
                          options.noise, object_rng, unit_normal, unit_uniform,
                          &point);
        if (!(point.x_px >= 0 && point.x_px < rig.width_px && point.y_px >= 0 &&
              point.y_px < rig.height_px)) {
          point.confidence = 0.0;
        }
      }
      view.clip.objects.push_back(std::move(track));
    }
    bundle.views.push_back(std::move(view));
  }
  bundle.ground_truth = std::move(truth);
  ValidateBundle(bundle, name);
  return bundle;
}

void CorruptKeypoint(double pixel_sigma_px, double drop_probability,
                     std::mt19937_64& rng,
                     std::normal_distribution<double>& unit_normal,
                     std::uniform_real_distribution<double>& unit_uniform,
                     Keypoint2D* keypoint) {
  if (pixel_sigma_px > 0) {
    keypoint->x_px += pixel_sigma_px * unit_normal(rng);
    keypoint->y_px += pixel_sigma_px * unit_normal(rng);
  }
  if (drop_probability > 0 && unit_uniform(rng) < drop_probability) {
    *keypoint = Keypoint2D{std::nan(""), std::nan(""), 0.0};
  }
}

std::vector<ViewSummary> SummarizeBundle(const ReferenceBundle& bundle) {
  std::vector<ViewSummary> summaries;
  for (const ReferenceView& view : bundle.views) {
    ViewSummary summary;
    summary.name = view.name;
    summary.num_frames = view.clip.num_frames();
    long present = 0, inside = 0, total = 0;
    double height_sum = 0.0;
    int height_frames = 0;
    for (int t = 0; t < view.clip.num_frames(); ++t) {
      double top = INFINITY, bottom = -INFINITY;
      for (int j = 0; j < view.clip.keypoints.num_keypoints(); ++j) {
        const Keypoint2D& k = view.clip.keypoints.at(t, j);
        ++total;
        if (!k.IsPresent()) continue;
        ++present;
        if (k.x_px >= 0 && k.y_px >= 0 && k.x_px < view.clip.image_width_px &&
            k.y_px < view.clip.image_height_px) {
          ++inside;
        }
        top = std::min(top, k.y_px);
        bottom = std::max(bottom, k.y_px);
      }
      if (bottom > top) {
        height_sum += bottom - top;
        ++height_frames;
      }
    }
    summary.present_fraction =
        total ? static_cast<double>(present) / total : 0.0;
    summary.in_image_fraction =
        present ? static_cast<double>(inside) / present : 0.0;
    summary.mean_height_px = height_frames ? height_sum / height_frames : 0.0;
    summaries.push_back(summary);
  }
  return summaries;
}

}  // namespace m2d
