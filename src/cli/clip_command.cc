// cli: `mimic2d clip` — make, convert and inspect 2D clips and bundles.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <memory>

#include "camera/camera_io.h"
#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"
#include "common/file_io.h"
#include "motion/bundle.h"
#include "motion/clip_io.h"

namespace m2d::cli {
namespace {

struct FromMotionArgs {
  MotionSourceArgs source;
  std::string output;
  std::string cameras_output;
  BundleFromMotionOptions options;
  bool follow = false;
};

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
  ReferenceBundle bundle = MakeBundleFromMotion(
      loaded.motion, loaded.keypoint_map, args.options, name);
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

int RunInfo(const std::string& path) {
  nlohmann::json json = ReadJsonFile(path);
  if (json.is_object() && json.value("format", "") == kBundleFormat) {
    PrintBundleSummary(ReadBundle(path), path);
    return 0;
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
      ->required();
  from_motion->add_option("--cameras-output", from->cameras_output,
                          "Also write the rig as a camera set (JSON)");
  AddBundleOptions(*from_motion, &from->options, &from->follow);
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
      ->required();
  resample_cmd->add_option("--fps", resample->fps, "Frame rate (Hz)")
      ->capture_default_str();
  resample_cmd->callback([run, resample] {
    *run = [resample] { return RunResample(*resample); };
  });

  auto info_path = std::make_shared<std::string>();
  CLI::App* info = clip->add_subcommand("info", "Summarize a clip or a bundle");
  info->add_option("file", *info_path, "Clip or bundle JSON")->required();
  info->callback(
      [run, info_path] { *run = [info_path] { return RunInfo(*info_path); }; });
}

}  // namespace m2d::cli
