// cli: `mimic2d keypoints` — COCO-17 keypoints of one person from an
// ordinary video (MoveNet on LibTorch), written as a 2D clip; optionally an
// overlay video for checking by eye.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "cli/commands.h"
#include "common/error.h"
#include "detect/movenet.h"
#include "detect/person_tracker.h"
#include "media/video_reader.h"
#include "media/video_writer.h"
#include "motion/clip_io.h"
#include "render/overlay.h"

namespace m2d::cli {
namespace {

struct KeypointsArgs {
  std::string video;
  std::string output;
  std::string overlay;
  std::string models;  // "": DefaultMoveNetFolder()
  MoveNetModel model = MoveNetModel::kLightning;
  std::string person = "track";  // track | largest | N
  int64_t max_frames = 0;        // 0: all
  int threads = 1;        // two collapse when another process wants a core
  bool keep_all = false;  // keep the frames before and after the person
  bool quiet = false;
};

PersonTrackerOptions TrackerOptionsFor(const std::string& person) {
  PersonTrackerOptions options;
  if (person == "track") {
    options.choice = PersonChoice::kTrack;
  } else if (person == "largest") {
    options.choice = PersonChoice::kLargest;
  } else {
    options.choice = PersonChoice::kIndex;
    const bool digits = !person.empty() && person.size() < 6 &&
                        std::all_of(person.begin(), person.end(), [](char c) {
                          return c >= '0' && c <= '9';
                        });
    if (!digits) {
      throw ConfigError(
          "--person must be track, largest or a number >= 0, not '" + person +
          "'");
    }
    options.person_index = std::stoi(person);
  }
  return options;
}

int RunKeypoints(const KeypointsArgs& args) {
  // Outline: open the video, load MoveNet, follow the person frame by
  // frame (progress line), write the clip atomically, and the overlay.
  SetDetectionThreads(args.threads);
  VideoReader reader(args.video);
  const VideoStreamInfo& info = reader.info();
  if (!(info.fps > 0))
    throw InputError(args.video, "has no frame rate (a still image?)");
  const MoveNet movenet(
      args.models.empty() ? DefaultMoveNetFolder() : args.models, args.model);
  PersonTracker tracker(movenet, TrackerOptionsFor(args.person));
  std::unique_ptr<Mp4Writer> overlay;
  if (!args.overlay.empty()) {
    Mp4Options options;
    options.fps = info.fps;
    overlay = std::make_unique<Mp4Writer>(args.overlay, info.width_px & ~1,
                                          info.height_px & ~1, options);
  }

  Clip2D clip;
  clip.fps = info.fps;
  clip.image_width_px = info.width_px;
  clip.image_height_px = info.height_px;
  std::vector<std::array<Keypoint2D, 17>> frames;
  std::vector<bool> has_person;
  RgbImage frame;
  int64_t found = 0, reacquired = 0;
  const int64_t total = args.max_frames > 0
                            ? args.max_frames
                            : std::max<int64_t>(info.num_frames, 0);
  const auto start = std::chrono::steady_clock::now();
  while ((args.max_frames == 0 ||
          static_cast<int64_t>(frames.size()) < args.max_frames) &&
         reader.Read(&frame)) {
    TrackedFrame tracked = tracker.Next(frame);
    std::array<Keypoint2D, 17> keypoints;
    keypoints.fill(Keypoint2D{std::nan(""), std::nan(""), 0.0});
    if (tracked.found) {
      keypoints = tracked.person.keypoints;
      ++found;
      reacquired += tracked.reacquired ? 1 : 0;
    }
    frames.push_back(keypoints);
    has_person.push_back(tracked.found);
    if (overlay) {
      RgbImage shown = frame;
      if (shown.width_px() != (info.width_px & ~1) ||
          shown.height_px() != (info.height_px & ~1)) {
        RgbImage even(info.width_px & ~1, info.height_px & ~1);
        even.Paste(shown, 0, 0);
        shown = even;
      }
      OverlayCanvas canvas(&shown);
      const OverlaySizes sizes = OverlaySizesForHeight(shown.height_px());
      if (tracked.found) {
        std::vector<Keypoint2D> points(keypoints.begin(), keypoints.end());
        for (Keypoint2D& k : points)
          if (k.confidence < 0.2) k.confidence = 0.0;  // drawn: confident only
        canvas.DrawSkeleton(
            Coco17Layout(), points,
            tracked.reacquired ? Rgb{255, 200, 0} : Rgb{0, 255, 120}, sizes);
      }
      char text[96];
      std::snprintf(text, sizeof(text), "frame %zu%s", frames.size(),
                    tracked.found ? (tracked.reacquired ? "  (detected)" : "")
                                  : "  (no person)");
      canvas.DrawLabel({{text}}, 8, 8, sizes);
      canvas.Finish();
      overlay->Write(shown);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    if (!args.quiet && (frames.size() % 10 == 0)) {
      const double rate = frames.size() / std::max(seconds, 1e-9);
      const double eta =
          total > 0 ? (total - static_cast<double>(frames.size())) / rate : 0.0;
      std::fprintf(
          stderr,
          "\rframe %zu%s | %.1f frames/s | person in %.0f%% | ETA %.0f s   ",
          frames.size(),
          total > 0 ? (" of " + std::to_string(total)).c_str() : "", rate,
          100.0 * found / frames.size(), std::max(0.0, eta));
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (!args.quiet) std::fprintf(stderr, "\n");
  if (frames.empty()) throw InputError(args.video, "has no frames");
  if (found == 0) {
    throw InputError(args.video, "no person found in any of its " +
                                     std::to_string(frames.size()) + " frames");
  }
  // The person's span: from the first frame that found them to the last.
  size_t first = 0, last = frames.size() - 1;
  if (!args.keep_all) {
    while (!has_person[first]) ++first;
    while (!has_person[last]) --last;
  }
  const int kept = static_cast<int>(last - first + 1);
  clip.keypoints = KeypointTrack(kept, 17);
  for (int t = 0; t < kept; ++t)
    for (int j = 0; j < 17; ++j) clip.keypoints.at(t, j) = frames[first + t][j];
  WriteClip(args.output, clip);
  if (overlay) overlay->Finish();
  std::printf(
      "%zu frames in %.1f s (%.1f frames/s): the person in %lld (%.1f%%) of "
      "video frames %zu-%zu (%.1f%% of the video)%s, found again by "
      "MultiPose %lld times (%d MultiPose runs)\nwrote %s: %d frames, "
      "video frames %zu-%zu\n",
      frames.size(), seconds, frames.size() / seconds,
      static_cast<long long>(found), 100.0 * found / (last - first + 1), first,
      last, 100.0 * found / frames.size(),
      tracker.ended() ? "; lost for good after that" : "",
      static_cast<long long>(reacquired), tracker.multipose_runs(),
      args.output.c_str(), kept, first, last);
  if (overlay) std::printf("wrote %s\n", args.overlay.c_str());
  return 0;
}

}  // namespace

void AddKeypointsCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<KeypointsArgs>();
  CLI::App* command = app.add_subcommand(
      "keypoints",
      "COCO-17 keypoints of one person from a video (MoveNet), as a 2D clip");
  command->add_option("video", args->video, "Video (or image) file")
      ->required();
  command->add_option("-o,--output", args->output, "Clip file to write (JSON)")
      ->check(WritableFile())
      ->required();
  command
      ->add_option("--model", args->model,
                   "Single-pose model: lightning (fast) or thunder (accurate)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, MoveNetModel>{
              {"lightning", MoveNetModel::kLightning},
              {"thunder", MoveNetModel::kThunder}},
          CLI::ignore_case))
      ->default_str("lightning");
  command
      ->add_option("--person", args->person,
                   "track (the best-scoring person first seen, followed), "
                   "largest (every frame) or N (the N-th from the left, "
                   "followed)")
      ->capture_default_str();
  command->add_option("--overlay", args->overlay,
                      "Also write this MP4: the frames with the keypoints");
  command->add_option("--models", args->models,
                      "Folder of the MoveNet files (default: $MIMIC2D_MODELS "
                      "or assets/models/movenet)");
  command->add_option("--max-frames", args->max_frames,
                      "Stop after this many frames (0: all)");
  command->add_option("--threads", args->threads, "LibTorch threads")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command->add_flag("--keep-all", args->keep_all,
                    "Keep every frame (default: from the first frame with the "
                    "person to the last)");
  command->add_flag("--quiet", args->quiet, "No progress line");
  command->callback(
      [run, args] { *run = [args] { return RunKeypoints(*args); }; });
}

}  // namespace m2d::cli
