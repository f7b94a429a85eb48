#include "cli/motion_source.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>

#include "cli/commands.h"
#include "common/error.h"
#include "motion/motion_io.h"
#include "sim/character.h"

namespace m2d::cli {

void AddMotionSourceOptions(CLI::App& command, MotionSourceArgs* args) {
  command.add_option("motion", args->path, "3D motion: DeepMimic .txt or .bvh")
      ->required();
  command.add_option(
      "--character", args->character,
      "Character config whose skeleton and keypoint map a DeepMimic file is "
      "read with (e.g. characters/dog.yaml; relative to assets/ unless "
      "absolute); --skeleton and --keypoint-map override it");
  command.add_option("--skeleton", args->skeleton,
                     "Skeleton YAML for DeepMimic files (default: "
                     "the character's, else assets/skeletons/humanoid.yaml)");
  command.add_option(
      "--keypoint-map", args->keypoint_map,
      "Keypoint map YAML (default: humanoid or CMU BVH COCO-17 map)");
  command
      .add_option("--bvh-scale", args->bvh_scale_m,
                  "Metres per BVH length unit")
      ->capture_default_str();
}

void AddBundleOptions(CLI::App& command, BundleFromMotionOptions* options,
                      bool* follow) {
  RigOptions& rig = options->rig;
  command.add_option("--fps", options->fps, "Frame rate of the 2D clips (Hz)")
      ->capture_default_str();
  command.add_option("--duration", options->duration_s,
                     "Clip length in seconds; longer than the motion loops a "
                     "looping motion (0: as is)");
  command.add_option("--views", rig.num_views, "Number of camera views")
      ->capture_default_str();
  command
      .add_option("--first-azimuth", rig.first_azimuth_deg,
                  "Azimuth of view 0 (deg)")
      ->capture_default_str();
  command
      .add_option("--azimuth-span", rig.azimuth_span_deg,
                  "Views spread over this arc (deg)")
      ->capture_default_str();
  command
      .add_option("--elevation", rig.elevation_deg, "Camera elevation (deg)")
      ->capture_default_str();
  command
      .add_option("--distance", rig.distance_m,
                  "Camera distance to the subject (m)")
      ->capture_default_str();
  command
      .add_option("--elevation-span", rig.elevation_span_deg,
                  "The last view's elevation exceeds the first's by this "
                  "(deg); views in between are spread evenly")
      ->capture_default_str();
  command
      .add_option("--distance-span", rig.distance_span_m,
                  "The last view's distance exceeds the first's by this (m)")
      ->capture_default_str();
  command
      .add_option("--aim", options->aim,
                  "Rig target: start (the first root) or middle (midway "
                  "along the subject's path)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, RigAim>{{"start", RigAim::kStartRoot},
                                        {"middle", RigAim::kPathMiddle}},
          CLI::ignore_case));
  command.add_option("--focal", rig.focal_px, "Focal length (px)")
      ->capture_default_str();
  command.add_option("--width", rig.width_px, "Image width (px)")
      ->capture_default_str();
  command.add_option("--height", rig.height_px, "Image height (px)")
      ->capture_default_str();
  command
      .add_option("--loop-heading", options->loop_heading,
                  "A looping motion repeated to --duration: accumulate (each "
                  "cycle turns by the cycle's net heading turn once more, as "
                  "DeepMimic wraps it) or straight (the turn spread back over "
                  "the cycle: a straight path)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, LoopHeading>{
              {SettingName(LoopHeading::kAccumulate), LoopHeading::kAccumulate},
              {SettingName(LoopHeading::kStraight), LoopHeading::kStraight}},
          CLI::ignore_case));
  command.add_flag("--follow", *follow,
                   "Cameras dolly along with the subject's ground path");
  command
      .add_option("--follow-smoothing", options->follow_smoothing_s,
                  "With --follow: the path is averaged over this window (s); "
                  "0 follows the root itself")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  command.add_option("--noise-px", options->noise.pixel_sigma_px,
                     "Detector noise: Gaussian sigma (px)");
  command.add_option("--drop", options->noise.drop_probability,
                     "Detector noise: probability a keypoint is missed");
  command.add_option(
      "--jitter-frames", options->noise.time_jitter_frames,
      "Detector noise: std. dev. of per-frame timing jitter (frames)");
  command
      .add_option("--seed", options->noise.seed, "Seed of the detector noise")
      ->capture_default_str();
}

LoadedMotion LoadMotionSource(const MotionSourceArgs& args) {
  std::string extension = std::filesystem::path(args.path).extension().string();
  LoadedMotion loaded;
  if (extension == ".bvh" || extension == ".BVH") {
    if (!(args.bvh_scale_m > 0)) {
      throw ConfigError("--bvh-scale must be positive");
    }
    if (!args.character.empty()) {
      throw ConfigError("--character applies to DeepMimic files: " + args.path +
                        " (BVH) carries its own skeleton");
    }
    loaded.motion = ReadBvhMotion(args.path, args.bvh_scale_m, args.fps);
    std::string map_path = args.keypoint_map.empty()
                               ? AssetPath("skeletons/cmu_bvh.coco17.yaml")
                               : args.keypoint_map;
    loaded.keypoint_map = LoadKeypointMap(map_path, *loaded.motion.skeleton);
    return loaded;
  }
  // The skeleton and keypoint map: given, else the character's, else the
  // humanoid's.
  std::string skeleton_path = AssetPath("skeletons/humanoid.yaml");
  std::string map_path = AssetPath("skeletons/humanoid.coco17.yaml");
  if (!args.character.empty()) {
    const CharacterConfig character =
        LoadCharacterConfig(AssetArgumentPath(args.character));
    skeleton_path = character.skeleton_path;
    map_path = character.keypoint_map_path;
  }
  if (!args.skeleton.empty()) skeleton_path = args.skeleton;
  if (!args.keypoint_map.empty()) map_path = args.keypoint_map;
  auto skeleton = std::make_shared<const Skeleton>(LoadSkeleton(skeleton_path));
  loaded.motion = ReadDeepMimicMotion(args.path, skeleton, args.fps);
  loaded.keypoint_map = LoadKeypointMap(map_path, *skeleton);
  return loaded;
}

void PrintBundleSummary(const ReferenceBundle& bundle,
                        const std::string& path) {
  std::printf("%s: bundle '%s', %zu views, %d frames at %.1f fps (%.2f s)\n",
              path.c_str(), bundle.name.c_str(), bundle.views.size(),
              bundle.num_frames(), bundle.fps,
              bundle.num_frames() / bundle.fps);
  size_t views_with_cameras = 0;
  for (const ReferenceView& view : bundle.views)
    views_with_cameras += !view.cameras.empty();
  std::string truth = "none";
  if (bundle.ground_truth) {
    truth = bundle.ground_truth->poses.empty()
                ? "3D keypoints"
                : "3D keypoints and " + bundle.ground_truth->skeleton_name +
                      " poses";
  }
  std::printf("  ground truth: %s\n", truth.c_str());
  std::printf("  true cameras: %s\n",
              views_with_cameras == bundle.views.size() ? "every view"
              : views_with_cameras == 0
                  ? "none (use cameras: estimate)"
                  : (std::to_string(views_with_cameras) + " of " +
                     std::to_string(bundle.views.size()) + " views")
                        .c_str());
  std::printf("  estimate: %s\n",
              bundle.estimate
                  ? ("every view (" + bundle.estimate->front().skeleton_name +
                     " poses, from mimic2d fit)")
                        .c_str()
                  : "none");
  for (const ObjectTrack2D& object : bundle.views.front().clip.objects) {
    // The object's 3D, where the bundle holds it.
    std::string where_3d;
    if (bundle.ground_truth &&
        FindObjectTrack(bundle.ground_truth->objects, object.name))
      where_3d = "ground truth";
    if (bundle.estimate &&
        FindObjectTrack(bundle.estimate->front().objects, object.name))
      where_3d += where_3d.empty() ? "estimate" : ", estimate";
    long seen = 0, total = 0;
    for (const ReferenceView& view : bundle.views) {
      for (const ObjectTrack2D& track : view.clip.objects) {
        if (track.name != object.name) continue;
        for (const Keypoint2D& point : track.points) {
          seen += point.IsPresent();
          ++total;
        }
      }
    }
    std::printf("  object: %s, seen in %.1f%% of the views' frames; 3D: %s\n",
                object.name.c_str(), total > 0 ? 100.0 * seen / total : 0.0,
                where_3d.empty() ? "none" : where_3d.c_str());
  }
  std::printf("  %-8s %8s %10s %10s %12s %10s\n", "view", "frames", "present%",
              "in-image%", "height(px)", "fit(px)");
  const std::vector<ViewSummary> summaries = SummarizeBundle(bundle);
  for (size_t k = 0; k < summaries.size(); ++k) {
    const ViewSummary& view = summaries[k];
    std::string fit = "-";
    if (bundle.estimate) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.2f",
                    (*bundle.estimate)[k].summary.mean_reprojection_px);
      fit = text;
    }
    std::printf("  %-8s %8d %10.1f %10.1f %12.1f %10s\n", view.name.c_str(),
                view.num_frames, 100 * view.present_fraction,
                100 * view.in_image_fraction, view.mean_height_px, fit.c_str());
  }
}

ReferenceBundle ReadMatchingTruth(const std::string& truth_path,
                                  const ReferenceBundle& bundle,
                                  const std::string& bundle_path) {
  ReferenceBundle truth = ReadBundle(truth_path);
  if (!truth.ground_truth) {
    throw InputError(truth_path, "--truth: the bundle holds no 3D truth");
  }
  if (truth.views.size() != bundle.views.size() ||
      truth.num_frames() != bundle.num_frames()) {
    throw InputError(truth_path,
                     "--truth: " + std::to_string(truth.views.size()) +
                         " views of " + std::to_string(truth.num_frames()) +
                         " frames, but " + bundle_path + " has " +
                         std::to_string(bundle.views.size()) + " of " +
                         std::to_string(bundle.num_frames()));
  }
  return truth;
}

}  // namespace m2d::cli
