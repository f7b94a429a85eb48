// cli: `mimic2d clip` — make, convert and inspect 2D clips and bundles.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "camera/camera_io.h"
#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"
#include "common/file_io.h"
#include "eval/fit_accuracy.h"
#include "eval/motion_feasibility.h"
#include "motion/bundle.h"
#include "motion/clip_io.h"
#include "sim/character.h"
#include "sim/object_replay.h"
#include "sim/simulation.h"

namespace m2d::cli {
namespace {

struct FromMotionArgs {
  MotionSourceArgs source;
  std::string output;
  std::string cameras_output;
  BundleFromMotionOptions options;
  bool follow = false;
  std::string ball;  // "", "auto" or "X,Y" (m)
};

// A ball's 3D truth for `sampled` (the bundle's frames): the character's
// `ball` scene replays the motion kinematically with the ball starting at
// rest where `where` says ("auto": in the path of the fastest kick, else
// "X,Y" on the floor, m). Reports where it went; InputError when the
// motion never touches it.
std::vector<ObjectTrack3D> KickedBall(const MotionSourceArgs& source,
                                      const Motion3D& sampled,
                                      const std::string& where) {
  const std::string extension =
      std::filesystem::path(source.path).extension().string();
  if (extension == ".bvh" || extension == ".BVH") {
    throw ConfigError("--ball replays the motion on the character: " +
                      source.path + " (BVH) is not in its skeleton");
  }
  const std::string config = AssetArgumentPath(
      source.character.empty() ? "characters/humanoid.yaml" : source.character);
  // Four physics steps a frame, as training's 120 Hz at 30 fps.
  auto character = Character::Load(config, "ball", 1.0 / (4.0 * sampled.fps));
  if (character->free_objects().size() != 1) {
    throw InputError(character->model_path(),
                     "--ball needs a scene with one free object, it has " +
                         std::to_string(character->free_objects().size()));
  }
  const double radius_m = character->free_objects().front().radius_m;
  if (!(radius_m > 0)) {
    throw InputError(character->model_path(),
                     "the scene's free object has no sphere: not a ball");
  }
  Eigen::Vector3d start_m;
  if (where == "auto") {
    const BallPlacement placement =
        PlaceBallInFootPath(*character, sampled, radius_m);
    start_m = placement.center_m;
    std::printf(
        "ball: placed at (%.2f, %.2f) m, ahead of %s at frame %d (%.1f m/s)\n",
        start_m.x(), start_m.y(),
        mj_id2name(character->model(), mjOBJ_BODY, placement.foot_body),
        placement.frame, placement.foot_speed_m_s);
  } else {
    double x = 0, y = 0;
    char rest = 0;
    if (std::sscanf(where.c_str(), "%lf,%lf%c", &x, &y, &rest) != 2 ||
        !std::isfinite(x) || !std::isfinite(y)) {
      throw ConfigError("--ball: '" + where +
                        "' is neither auto nor X,Y in metres");
    }
    start_m = {x, y, radius_m};
  }
  std::vector<ObjectTrack3D> tracks =
      ReplayObjectsAlongMotion(*character, sampled, {start_m});
  const std::vector<Eigen::Vector3d>& path = tracks.front().positions_m;
  double top_speed_m_s = 0.0;
  int kicked = -1;
  for (size_t t = 1; t < path.size(); ++t) {
    const double speed = (path[t] - path[t - 1]).norm() * sampled.fps;
    if (speed > 0.5 && kicked < 0) kicked = static_cast<int>(t) - 1;
    top_speed_m_s = std::max(top_speed_m_s, speed);
  }
  if (kicked < 0) {
    throw InputError(source.path,
                     "the ball at (" + std::to_string(start_m.x()) + ", " +
                         std::to_string(start_m.y()) +
                         ") m is never kicked: the motion does not reach "
                         "it (give --ball X,Y where a foot passes)");
  }
  double top_height_m = 0.0;
  for (const Eigen::Vector3d& p : path)
    top_height_m = std::max(top_height_m, p.z() - radius_m);
  std::printf(
      "ball: kicked at frame %d, up to %.1f m/s and %.2f m off the floor; "
      "at (%.2f, %.2f, %.2f) m at the end\n",
      kicked, top_speed_m_s, top_height_m, path.back().x(), path.back().y(),
      path.back().z());
  return tracks;
}

struct ConvertArgs {
  std::string input;
  std::string output;
  DetectionReadOptions read;
};

int RunFromMotion(FromMotionArgs& args) {
  args.options.follow =
      args.follow ? CameraFollow::kRootDolly : CameraFollow::kStatic;
  LoadedMotion loaded = LoadMotionSource(args.source);
  std::string name = std::filesystem::path(args.source.path).stem().string();
  std::vector<ObjectTrack3D> objects;
  if (!args.ball.empty()) {
    objects = KickedBall(args.source,
                         SampleMotionForBundle(loaded.motion, args.options),
                         args.ball);
  }
  ReferenceBundle bundle = MakeBundleFromMotion(
      loaded.motion, loaded.keypoint_map, args.options, name, objects);
  WriteBundle(args.output, bundle);
  if (!args.cameras_output.empty()) {
    std::vector<NamedCamera> cameras;
    for (const ReferenceView& view : bundle.views) {
      cameras.push_back({view.name, view.cameras.front()});
    }
    WriteCameraSet(args.cameras_output, cameras);
  }
  PrintBundleSummary(bundle, args.output);
  return 0;
}

int RunConvert(const ConvertArgs& args) {
  Clip2D clip = ReadClipAuto(args.input, args.read);
  WriteClip(args.output, clip);
  std::cout << "wrote " << args.output << ": " << clip.num_frames()
            << " frames, " << clip.layout->name << ", " << clip.fps << " fps\n";
  return 0;
}

struct StripArgs {
  std::string input;
  std::string output;
};

int RunStrip(const StripArgs& args) {
  ReferenceBundle bundle = ReadBundle(args.input);
  const bool had_truth = bundle.ground_truth.has_value();
  const bool had_estimate = bundle.estimate.has_value();
  bundle = StripBundle(std::move(bundle));
  WriteBundle(args.output, bundle);
  std::cout << "dropped" << (had_truth ? " the 3D ground truth," : "")
            << " the true cameras" << (had_estimate ? ", the estimate" : "")
            << "; kept the 2D of " << bundle.views.size() << " views\n";
  PrintBundleSummary(bundle, args.output);
  return 0;
}

struct ResampleArgs {
  std::string input;
  std::string output;
  double fps = 30.0;
};

int RunResample(const ResampleArgs& args) {
  const Clip2D clip = ReadClip(args.input);
  const Clip2D resampled = ResampleClip(clip, args.fps);
  WriteClip(args.output, resampled);
  std::cout << "wrote " << args.output << ": " << resampled.num_frames()
            << " frames at " << resampled.fps << " fps (from "
            << clip.num_frames() << " at " << clip.fps << " fps)\n";
  return 0;
}

struct InfoArgs {
  std::string path;
  // A bundle holding the truth of `path`'s fitted estimate: each view's fit
  // is measured against it (focal, pitch, roll, MPJPE, PA-MPJPE), as `fit
  // --truth` does after fitting, without fitting again.
  std::string truth;
  std::string character = "characters/humanoid.yaml";
};

// Each view's estimate in `bundle` against `truth` (ReadMatchingTruth's),
// one line per view and their mean.
void PrintFitAccuracy(const ReferenceBundle& bundle, const InfoArgs& args) {
  if (!bundle.estimate) {
    throw InputError(args.path,
                     "--truth: the bundle holds no estimate to measure (fit "
                     "it first: mimic2d fit)");
  }
  const ReferenceBundle truth =
      ReadMatchingTruth(args.truth, bundle, args.path);
  auto character = LoadCharacterForSimulation(AssetArgumentPath(args.character),
                                              "flat", SimulationOptions());
  std::vector<FitAccuracy> accuracies;
  for (size_t view = 0; view < bundle.views.size(); ++view) {
    accuracies.push_back(MeasureFitAccuracy((*bundle.estimate)[view],
                                            truth.views[view].cameras,
                                            *truth.ground_truth, *character));
    std::printf("view %zu/%zu (%s), against the truth: %s\n", view + 1,
                bundle.views.size(), bundle.views[view].name.c_str(),
                accuracies.back().BriefReport().c_str());
  }
  std::printf("mean over the views, against the truth: %s\n",
              MeanFitAccuracy(accuracies).BriefReport().c_str());
}

int RunInfo(const InfoArgs& args) {
  const std::string& path = args.path;
  nlohmann::json json = ReadJsonFile(path);
  if (json.is_object() && json.value("format", "") == kBundleFormat) {
    const ReferenceBundle bundle = ReadBundle(path);
    PrintBundleSummary(bundle, path);
    if (!args.truth.empty()) PrintFitAccuracy(bundle, args);
    return 0;
  }
  if (!args.truth.empty()) {
    throw InputError(path, "--truth: a clip holds no fit to measure");
  }
  Clip2D clip = ReadClip(path);
  long present = 0;
  for (int t = 0; t < clip.num_frames(); ++t) {
    for (int j = 0; j < clip.keypoints.num_keypoints(); ++j) {
      present += clip.keypoints.at(t, j).IsPresent();
    }
  }
  std::cout << path << ": clip, layout " << clip.layout->name << ", "
            << clip.num_frames() << " frames at " << clip.fps << " fps, "
            << clip.image_width_px << "x" << clip.image_height_px
            << " px, keypoints present "
            << 100.0 * present /
                   (clip.num_frames() * clip.keypoints.num_keypoints())
            << "%, objects " << clip.objects.size() << "\n";
  return 0;
}

struct FeasibilityArgs {
  std::string input;
  std::string poses = "truth";  // truth | estimate
  std::string character = "characters/humanoid.yaml";
  std::string frames_csv;
  int opening_frames = 10;
  std::string torque_limit = "servo";
  FeasibilityOptions options;
};

// One row of the feasibility table: a set of poses and what they take.
struct FeasibilityRow {
  std::string name;
  MotionFeasibility result;
};

void PrintFeasibilityTable(const std::vector<FeasibilityRow>& rows,
                           const Character& character, int opening_frames) {
  std::printf("%-10s %6s %12s %13s %13s %15s %14s %9s %14s %8s  %s; %s\n",
              "poses", "frames", "over torque", "out of range", "out of reach",
              "self-overlap", "floor cannot", "airborne", "flight force",
              "opening", "worst hinge (peak / limit, frames over)",
              "furthest out of range (deg past, frames)");
  for (const FeasibilityRow& row : rows) {
    const MotionFeasibility& r = row.result;
    double opening_ratio = 0.0;
    for (int t = 0; t < std::min(opening_frames, r.num_frames); ++t) {
      opening_ratio = std::max(opening_ratio, r.frames[t].worst_torque_ratio);
    }
    const HingeDemand* worst = r.WorstHinge();
    char worst_text[128] = "-";
    if (worst) {
      std::snprintf(worst_text, sizeof(worst_text), "%s %.2f, %d of %d",
                    worst->actuator.c_str(), worst->peak_ratio,
                    worst->frames_over_limit, worst->frames_measured);
    }
    const HingeDemand* out_of_range = r.WorstRangeHinge();
    char range_text[128] = "-";
    if (out_of_range) {
      std::snprintf(range_text, sizeof(range_text), "%s %.1f, %d",
                    out_of_range->actuator.c_str(),
                    out_of_range->peak_range_excess_rad * 180.0 / M_PI,
                    out_of_range->frames_out_of_range);
    }
    std::printf(
        "%-10s %6d %11.1f%% %12.1f%% %5.1f%% %4.2f m %6.1f%% %4.1f cm "
        "%13.1f%% %9d %11.2f bw %8.2f  %s; %s\n",
        row.name.c_str(), r.num_frames,
        100.0 * r.FramesOverTorqueLimit() / r.num_frames,
        100.0 * r.FramesOutOfRange() / r.num_frames,
        100.0 * r.FramesOutOfReach() / r.num_frames, r.WorstReachErrorM(),
        100.0 * r.FramesSelfPenetrating() / r.num_frames,
        r.DeepestSelfPenetration()
            ? 100.0 * r.DeepestSelfPenetration()->self_penetration_m
            : 0.0,
        100.0 * r.FramesFloorCannotExplain() / r.num_frames, r.AirborneFrames(),
        r.MeanForceInFlightBodyWeights(), opening_ratio, worst_text,
        range_text);
  }
  std::printf(
      "over torque: frames in which a hinge the floor cannot reach needs more "
      "than its limit; out of range: frames in which some hinge angle has no "
      "solution within its joint range (%.1f deg of tolerance); out of "
      "reach: frames whose nearest pose within every range leaves a body "
      "keypoint more than %.2f m off, and the worst distance; "
      "self-overlap: frames in which two of the character's own geoms "
      "overlap by more than %.1f cm, and the deepest; floor "
      "cannot: a force needed in flight, a pull or a "
      "slip; flight force: mean external force while airborne, in %s's "
      "body weights; opening: the worst torque / limit over the first %d "
      "frames\n",
      rows.empty() ? 0.0 : rows[0].result.range_tolerance_rad * 180.0 / M_PI,
      rows.empty() ? 0.0 : rows[0].result.reach_tolerance_m,
      rows.empty() ? 0.0 : 100.0 * rows[0].result.penetration_tolerance_m,
      character.name().c_str(), opening_frames);
}

void WriteFeasibilityFramesCsv(const std::string& path,
                               const std::vector<FeasibilityRow>& rows) {
  std::string csv =
      "poses,frame,touching,worst_torque_ratio,worst_hinge,"
      "range_excess_deg,range_hinge,reach_error_m,self_penetration_m,"
      "self_contact,force_x_n,force_y_n,force_z_n,"
      "force_in_flight,pulls_floor,slips\n";
  char line[256];
  for (const FeasibilityRow& row : rows) {
    const MotionFeasibility& r = row.result;
    for (int t = 0; t < r.num_frames; ++t) {
      const FrameDemand& f = r.frames[t];
      std::snprintf(
          line, sizeof(line),
          "%s,%d,%d,%.3f,%s,%.1f,%s,%.3f,%.3f,%s,%.1f,%.1f,%.1f,%d,%d,%d\n",
          row.name.c_str(), t, f.touching ? 1 : 0, f.worst_torque_ratio,
          f.worst_hinge < 0 ? "" : r.hinges[f.worst_hinge].actuator.c_str(),
          f.worst_range_excess_rad * 180.0 / M_PI,
          f.worst_range_hinge < 0
              ? ""
              : r.hinges[f.worst_range_hinge].actuator.c_str(),
          f.reach_error_m, f.self_penetration_m, f.self_contact.c_str(),
          f.external_force_n.x(), f.external_force_n.y(),
          f.external_force_n.z(), f.force_in_flight ? 1 : 0,
          f.pulls_floor ? 1 : 0, f.slips ? 1 : 0);
      csv += line;
    }
  }
  WriteFileAtomic(path, csv);
}

int RunFeasibility(const FeasibilityArgs& args) {
  // Outline: the bundle's truth or each view's fitted poses, checked against
  // the character's skeleton; the inverse dynamics of each; a table.
  FeasibilityOptions options = args.options;
  ParseSetting(args.torque_limit, &options.torque_limit);
  options.Validate();
  const ReferenceBundle bundle = ReadBundle(args.input);
  auto character = Character::Load(AssetArgumentPath(args.character), "flat",
                                   SimulationOptions().physics_timestep_s());
  const std::string& skeleton = character->skeleton().name;
  std::vector<FeasibilityRow> rows;
  const auto add_row = [&](const std::string& name,
                           const std::string& pose_skeleton,
                           const std::vector<Pose3D>& poses) {
    if (poses.empty()) {
      throw InputError(args.input, name + " has no 3D poses to measure");
    }
    if (pose_skeleton != skeleton) {
      throw InputError(args.input,
                       name + "'s poses are of skeleton '" + pose_skeleton +
                           "', the character's is '" + skeleton + "'");
    }
    rows.push_back({name, MeasureMotionFeasibility(*character, poses,
                                                   bundle.fps, options)});
  };
  if (args.poses == "truth") {
    if (!bundle.ground_truth) {
      throw InputError(args.input,
                       "has no 3D ground truth (--poses estimate measures a "
                       "fit's poses)");
    }
    add_row("truth", bundle.ground_truth->skeleton_name,
            bundle.ground_truth->poses);
  } else {
    if (!bundle.estimate) {
      throw InputError(args.input,
                       "has no estimate: fit it first (mimic2d fit)");
    }
    for (size_t v = 0; v < bundle.estimate->size(); ++v) {
      const ViewEstimate& estimate = (*bundle.estimate)[v];
      add_row(bundle.views[v].name, estimate.skeleton_name, estimate.poses);
    }
  }
  std::printf(
      "feasibility of %s (%s poses) for %s, torque_limit %s: "
      "contact within %.3f m of the floor, friction %.2f, force "
      "tolerance %.2f body weights\n",
      args.input.c_str(), args.poses.c_str(), character->name().c_str(),
      SettingName(options.torque_limit), options.contact_height_m,
      options.friction_coefficient, options.force_tolerance_body_weights);
  PrintFeasibilityTable(rows, *character, args.opening_frames);
  if (!args.frames_csv.empty()) {
    WriteFeasibilityFramesCsv(args.frames_csv, rows);
    std::printf("wrote %s\n", args.frames_csv.c_str());
  }
  return 0;
}

}  // namespace

void AddClipCommand(CLI::App& app, CommandRun* run) {
  CLI::App* clip = app.add_subcommand(
      "clip", "Make, convert and inspect 2D clips and reference bundles");
  clip->require_subcommand(1);

  auto from = std::make_shared<FromMotionArgs>();
  CLI::App* from_motion =
      clip->add_subcommand("from-motion",
                           "3D motion (DeepMimic .txt or .bvh) + camera rig -> "
                           "multi-view 2D reference bundle");
  AddMotionSourceOptions(*from_motion, &from->source);
  from_motion
      ->add_option("-o,--output", from->output, "Bundle file to write (JSON)")
      ->check(WritableFile())
      ->required();
  from_motion
      ->add_option("--cameras-output", from->cameras_output,
                   "Also write the rig as a camera set (JSON)")
      ->check(WritableFile());
  AddBundleOptions(*from_motion, &from->options, &from->follow);
  from_motion->add_option(
      "--ball", from->ball,
      "Add a ball the motion kicks (the character's 'ball' scene; its 3D "
      "truth simulated with the character replaying the motion): auto (in "
      "the path of the fastest foot near the floor) or X,Y on the floor (m)");
  from_motion->callback(
      [run, from] { *run = [from] { return RunFromMotion(*from); }; });

  auto convert = std::make_shared<ConvertArgs>();
  CLI::App* convert_cmd =
      clip->add_subcommand("convert",
                           "Detector output (COCO/ViTPose/MMPose JSON, "
                           "OpenPose folder) -> mimic2d clip");
  convert_cmd
      ->add_option("input", convert->input,
                   "Detections: a JSON file or an OpenPose folder")
      ->required();
  convert_cmd->add_option("-o,--output", convert->output, "Clip file to write")
      ->check(WritableFile())
      ->required();
  convert_cmd->add_option("--track-id", convert->read.track_id,
                          "Person to follow (-1: the largest per frame)");
  convert_cmd->add_option("--fps", convert->read.fps,
                          "Frame rate of the video (Hz)");
  convert_cmd->add_option("--width", convert->read.image_width_px,
                          "Image width (px)");
  convert_cmd->add_option("--height", convert->read.image_height_px,
                          "Image height (px)");
  convert_cmd->callback(
      [run, convert] { *run = [convert] { return RunConvert(*convert); }; });

  auto strip = std::make_shared<StripArgs>();
  CLI::App* strip_cmd = clip->add_subcommand(
      "strip",
      "Drop a bundle's 3D ground truth, true cameras and any estimate, "
      "keeping the 2D (what a user with videos has)");
  strip_cmd->add_option("bundle", strip->input, "Bundle JSON to strip")
      ->required();
  strip_cmd->add_option("-o,--output", strip->output, "Bundle file to write")
      ->check(WritableFile())
      ->required();
  strip_cmd->callback(
      [run, strip] { *run = [strip] { return RunStrip(*strip); }; });

  auto resample = std::make_shared<ResampleArgs>();
  CLI::App* resample_cmd = clip->add_subcommand(
      "resample",
      "A clip at another frame rate (keypoints interpolated), e.g. a 10 fps "
      "video's clip at the 30 Hz control rate");
  resample_cmd->add_option("clip", resample->input, "Clip JSON")->required();
  resample_cmd->add_option("-o,--output", resample->output, "Clip to write")
      ->check(WritableFile())
      ->required();
  resample_cmd->add_option("--fps", resample->fps, "Frame rate (Hz)")
      ->capture_default_str();
  resample_cmd->callback([run, resample] {
    *run = [resample] { return RunResample(*resample); };
  });

  auto feasibility = std::make_shared<FeasibilityArgs>();
  CLI::App* feasibility_cmd = clip->add_subcommand(
      "feasibility",
      "Whether a bundle's 3D poses (the truth, or each view's fit) are "
      "physically possible for the character: the torques and the floor's "
      "push that following them exactly takes (inverse dynamics)");
  feasibility_cmd->add_option("bundle", feasibility->input, "Bundle JSON")
      ->required();
  feasibility_cmd
      ->add_option("--poses", feasibility->poses,
                   "truth (the bundle's 3D ground truth) or estimate (each "
                   "view's fitted poses)")
      ->check(CLI::IsMember({"truth", "estimate"}))
      ->capture_default_str();
  feasibility_cmd
      ->add_option("--character", feasibility->character,
                   "character config (relative to assets/ unless absolute)")
      ->capture_default_str();
  feasibility_cmd
      ->add_option("--frames", feasibility->frames_csv,
                   "Also write every frame's worst hinge and external force "
                   "(CSV)")
      ->check(WritableFile());
  feasibility_cmd
      ->add_option("--opening", feasibility->opening_frames,
                   "Frames counted as the clip's opening in the table")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  feasibility_cmd
      ->add_option("--contact-height", feasibility->options.contact_height_m,
                   "A body this close to the floor may touch it (m)")
      ->capture_default_str();
  feasibility_cmd
      ->add_option("--torque-limit", feasibility->torque_limit,
                   "what the torque limits bound: servo (the damping on top, "
                   "as env.torque_limit: servo trains) or pd (the whole PD)")
      ->check(CLI::IsMember({"servo", "pd"}))
      ->capture_default_str();
  feasibility_cmd->callback([run, feasibility] {
    *run = [feasibility] { return RunFeasibility(*feasibility); };
  });

  auto info_args = std::make_shared<InfoArgs>();
  CLI::App* info = clip->add_subcommand("info", "Summarize a clip or a bundle");
  info->add_option("file", info_args->path, "Clip or bundle JSON")->required();
  info->add_option("--truth", info_args->truth,
                   "bundle holding the 3D truth and true cameras of the "
                   "file's fitted estimate (e.g. the original of the bundle "
                   "that was stripped and fitted): each view's fit is "
                   "measured against it (focal, pitch, roll, MPJPE, "
                   "PA-MPJPE) without fitting again");
  info->add_option("--character", info_args->character,
                   "character config the fit posed (relative to assets/ "
                   "unless absolute); with --truth")
      ->capture_default_str();
  info->callback(
      [run, info_args] { *run = [info_args] { return RunInfo(*info_args); }; });
}

}  // namespace m2d::cli
