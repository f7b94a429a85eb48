// cli: `mimic2d gen train` — learn the 2D motion generator (tokenizer, then
// prior) from a config; `mimic2d generate` — stream generated 2D motion into
// a clip placed under a chosen camera view.
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "camera/rig.h"
#include "cli/commands.h"
#include "cli/motion_source.h"
#include "cli/policy_runs.h"
#include "common/error.h"
#include "common/file_io.h"
#include "env/reference.h"
#include "env/reference_stream.h"
#include "eval/evaluator.h"
#include "fit/camera_model.h"
#include "fit/fit.h"
#include "fit/fit_config.h"
#include "gen/gen_config.h"
#include "gen/gen_trainer.h"
#include "gen/generated_stream.h"
#include "gen/generator.h"
#include "motion/clip_io.h"
#include "render/episode_renderer.h"
#include "rl/torch_policy.h"

namespace m2d::cli {
namespace {

std::atomic<bool> g_gen_stop_requested{false};
void RequestGenStop(int) { g_gen_stop_requested.store(true); }

struct GenTrainArgs {
  std::string config_path;
  bool resume = false;
  bool list_settings = false;
  std::string run_dir;           // overrides run.run_dir
  int64_t tokenizer_steps = -1;  // overrides tokenizer.steps (-1: keep)
  int64_t prior_steps = -1;      // overrides prior.steps
};

// The dataset of `motions` (files) seen from a config's views.
GenDataset LoadGenDataset(const GenConfig& config,
                          const std::vector<std::string>& motions) {
  std::vector<GenMotionSource> sources;
  for (const std::string& path : motions) {
    MotionSourceArgs args;
    args.path = path;
    LoadedMotion loaded = LoadMotionSource(args);
    sources.push_back({std::filesystem::path(path).stem().string(),
                       std::move(loaded.motion),
                       std::move(loaded.keypoint_map)});
  }
  return BuildGenDataset(sources, config.data.views, config.data.fps,
                         config.data.loop_to_s, config.data.loop_heading);
}

int RunGenTrain(const GenTrainArgs& args) {
  if (args.list_settings) {
    std::printf("%s", GenSettingsReference().c_str());
    return 0;
  }
  if (args.config_path.empty())
    throw InputError("",
                     "gen train: give a config (e.g. configs/gen/clips.yaml)");
  GenConfig config = LoadGenConfig(args.config_path);
  if (!args.run_dir.empty()) config.run.run_dir = args.run_dir;
  if (args.tokenizer_steps >= 0) config.tokenizer.steps = args.tokenizer_steps;
  if (args.prior_steps >= 0) config.prior.steps = args.prior_steps;
  std::signal(SIGINT, RequestGenStop);
  std::signal(SIGTERM, RequestGenStop);
  const GenDataset dataset = LoadGenDataset(config, config.data.motions);
  std::printf(
      "gen train %s -> %s: %zu sequences (%zu motions x %d views), %lld "
      "frames at %.0f fps (%.1f min of 2D)\n",
      args.config_path.c_str(), config.run.run_dir.c_str(),
      dataset.sequences.size(), config.data.motions.size(),
      config.data.views.num_views(),
      static_cast<long long>(dataset.num_frames()), dataset.fps,
      dataset.num_frames() / dataset.fps / 60.0);
  auto report = [](const GenProgress& p) {
    const double eta_s =
        p.step > 0 ? p.seconds / p.step * (p.steps - p.step) : 0.0;
    if (p.stage == GenStage::kTokenizer) {
      std::printf(
          "tokenizer %7lld/%lld | loss %.4f (canonical %.4f absolute %.4f "
          "velocity %.4f commit %.4f) | perplexity %6.1f, %3d codes used, %3d "
          "reset | lr %.1e | %.1f steps/s, %d threads | ETA %.0f s\n",
          static_cast<long long>(p.step), static_cast<long long>(p.steps),
          p.loss, p.canonical_loss, p.absolute_loss, p.velocity_loss,
          p.commit_loss, p.perplexity, p.used_codes, p.reset_codes,
          p.learning_rate, p.step / std::max(1e-9, p.seconds), p.torch_threads,
          eta_s);
    } else {
      std::printf(
          "prior     %7lld/%lld | cross-entropy %.4f nats (held out %.4f) | "
          "next-code accuracy %5.1f%% | lr %.1e | %.1f steps/s, %d threads "
          "| ETA %.0f s\n",
          static_cast<long long>(p.step), static_cast<long long>(p.steps),
          p.loss, p.validation_loss, 100.0 * p.accuracy, p.learning_rate,
          p.step / std::max(1e-9, p.seconds), p.torch_threads, eta_s);
    }
    std::fflush(stdout);
  };
  const GenTrainSummary summary = TrainGenerator(config, dataset, args.resume,
                                                 &g_gen_stop_requested, report);
  std::printf("%s", summary.BriefReport().c_str());
  return summary.interrupted ? 130 : 0;
}

// Where a tracked generation starts. The generated 2D has no 3D and no
// camera: like a user's video, it is fitted.
enum class GeneratedStart {
  // The fit (fit/fit.h) of the stream's first seconds as a user's clip
  // (a moving camera, the focal --focal): its first pose and camera.
  kFit,
  // The default pose placed under the first frame, facing the --view
  // camera (before 2026-11-26 the only start).
  kDefault,
};

// With GeneratedStart::kFit: the start fit's camera tilt. A generated
// clip's view is chosen (--view), not filmed: its pitch and roll are known
// and only approximated by the 2D, which a fit of a few seconds reads
// 5-10 deg off (docs/generation.md 4b, "The measure's camera, the horizon
// and the fits' tilt").
enum class StartTilt {
  kView,  // the --view camera's pitch and roll, held (fit/fit.h tilt_known)
  kFit,   // estimated with the rest, as for a user's video (before 2026-12-07)
};

struct GenerateArgs {
  std::string run_dir;  // holds tokenizer.pt and prior.pt
  std::string output;
  double seconds = 10.0;
  GenerationOptions generation;                  // --seed, sampling, placement
  std::vector<double> view = {30.0, 10.0, 4.5};  // azimuth, elevation, distance
  int motion = 0;  // data.motions index, for a prior conditioned on it
  // With --policy and a prior conditioned on the motion: generation g
  // draws motion g mod the config's motions instead of `motion`.
  bool each_motion = false;
  double focal_px = 1000.0;
  // --policy: a tracker checkpoint driven along `generations` streams
  // (seeds seed, seed + 1, ...); --video: the first one drawn.
  std::string policy;
  int generations = 1;
  std::vector<double> azimuths_deg;  // with --policy: views (default --view's)
  std::string video;
  std::string frames_csv;  // with --policy: every rollout's per-frame errors
  // With --policy: where each rollout starts and which camera it is seen by.
  GeneratedStart start = GeneratedStart::kFit;
  double start_fit_s = 2.0;  // with kFit: the stream's first seconds fitted
  StartTilt start_tilt = StartTilt::kView;  // with kFit: the camera's tilt
  // With kFit: FitOptions YAML for that fit ("": the defaults); whatever
  // the file says, the camera is moving and the focal is --focal's.
  std::string fit_config;
  // With kFit: the rollout starts this far into the stream (s), from the
  // fit's pose there; the frames before it are not tracked. Negative: the
  // middle of the fitted seconds (StartAtS).
  double start_at_s = -1.0;
  // With --policy: track every view of this bundle's (or clip's) 2D instead
  // of generations, under the same protocol (the control).
  std::string real;
};

// Where a fitted start lies in the stream (s): --start-at-s, by default
// the middle of the fitted seconds. A window's edge is its least
// constrained frame, and the prior's first codes follow the start token
// alone: started at 1 s of 2 instead of 0, the walk2d tracker followed 26
// of 40 generated walks for 60 s instead of 20 (docs/generation.md 4b).
double StartAtS(const GenerateArgs& args) {
  return args.start_at_s >= 0.0 ? args.start_at_s : 0.5 * args.start_fit_s;
}

// The camera at `azimuth_deg` and --view's elevation and distance: the
// rig's, aimed at the origin.
PinholeCamera ViewCamera(const GenerateArgs& args, double azimuth_deg) {
  RigOptions rig;
  rig.num_views = 1;
  rig.first_azimuth_deg = azimuth_deg;
  rig.elevation_deg = args.view[1];
  rig.distance_m = args.view[2];
  rig.focal_px = args.focal_px;
  rig.Validate();
  return MakeRig(rig).front().camera;
}

// The first frame's root and scale: the character standing at the origin,
// seen by `camera` (what the tracker starts from).
void StandingPlacement(const PinholeCamera& camera, Eigen::Vector2d* root_px,
                       double* scale_px) {
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(AssetPath("skeletons/humanoid.yaml")));
  const KeypointMap map =
      LoadKeypointMap(AssetPath("skeletons/humanoid.coco17.yaml"), *skeleton);
  Pose3D rest;
  rest.local_rotations.assign(skeleton->num_joints(),
                              Eigen::Quaterniond::Identity());
  std::vector<Eigen::Vector3d> points = KeypointPositions(*skeleton, map, rest);
  double lowest_m = points.front().z();
  for (const auto& point : points) lowest_m = std::min(lowest_m, point.z());
  Clip2D frame;
  frame.keypoints = KeypointTrack(1, static_cast<int>(points.size()));
  for (size_t j = 0; j < points.size(); ++j) {
    const Projection p =
        camera.Project(points[j] - Eigen::Vector3d(0, 0, lowest_m));
    frame.keypoints.at(0, static_cast<int>(j)) = {p.pixel_px.x(),
                                                  p.pixel_px.y(), 1.0};
  }
  if (!RootAndScale(frame.keypoints.frame(0), *frame.layout, root_px,
                    scale_px)) {
    throw ConfigError(
        "generate: the standing character is not visible from "
        "--view");
  }
}

// One stream to track: a generation, or a recorded view (--real).
struct TrackedSource {
  std::string label;  // "azimuth 30 deg, generation 2 (seed 2)"
  std::function<std::unique_ptr<ReferenceStream>()> open;
  // --start default: the camera the default pose is placed under, and the
  // first frame's root and scale.
  PinholeCamera view_camera;
  Eigen::Vector2d root_px = Eigen::Vector2d::Zero();
  double scale_px = 0.0;
};

// The first `seconds` of `source`, as a clip: the frames the tracker will
// be handed, drawn by a stream of their own.
Clip2D FirstFramesOf(const TrackedSource& source, double seconds) {
  std::unique_ptr<ReferenceStream> stream = source.open();
  Clip2D clip = stream->format();
  const int frames = std::max(1, static_cast<int>(seconds * clip.fps + 0.5));
  const int num_keypoints = clip.layout->num_keypoints();
  clip.keypoints = KeypointTrack(frames, num_keypoints);
  std::vector<Keypoint2D> frame;
  int read = 0;
  while (read < frames && stream->Next(&frame)) {
    for (int j = 0; j < num_keypoints; ++j)
      clip.keypoints.at(read, j) = frame[j];
    ++read;
  }
  if (read < frames) clip.keypoints = KeypointTrack(0, num_keypoints);
  return clip;
}

// The streams --policy tracks: --generations generations from every
// azimuth, or with --real every view of a recorded bundle's 2D (the same
// protocol on real motion: the control the generated figures are read
// against).
std::vector<TrackedSource> TrackedSources(const GenerateArgs& args) {
  std::vector<TrackedSource> sources;
  if (!args.real.empty()) {
    auto bundle = std::make_shared<const ReferenceBundle>(
        ReadBundleOrClip(args.real));  // the 2D only: no camera, no 3D
    for (size_t v = 0; v < bundle->views.size(); ++v) {
      TrackedSource source;
      source.label = "real " + bundle->name + " " + bundle->views[v].name;
      source.open = [bundle, v] {
        return std::make_unique<ClipStream>(bundle->views[v].clip);
      };
      sources.push_back(std::move(source));
    }
    return sources;
  }
  const GenConfig generator_config = ReadPriorConfig(args.run_dir);
  const std::vector<double> azimuths_deg =
      args.azimuths_deg.empty() ? std::vector<double>{args.view[0]}
                                : args.azimuths_deg;
  for (double azimuth_deg : azimuths_deg) {
    const PinholeCamera view_camera = ViewCamera(args, azimuth_deg);
    Eigen::Vector2d root_px;
    double scale_px = 0.0;
    StandingPlacement(view_camera, &root_px, &scale_px);
    for (int g = 0; g < args.generations; ++g) {
      GeneratedStreamOptions options;
      options.generation = args.generation;
      options.generation.seed = args.generation.seed + g;
      const int motion =
          args.each_motion ? g % generator_config.prior_motions() : args.motion;
      options.generation.view =
          GenerationView(generator_config, azimuth_deg, args.view[1], motion);
      options.first_root_px = root_px;
      options.first_scale_px = scale_px;
      options.image_width_px = view_camera.intrinsics().width_px;
      options.image_height_px = view_camera.intrinsics().height_px;
      TrackedSource source;
      char label[128];
      std::snprintf(label, sizeof(label),
                    "azimuth %.0f deg, generation %d (seed %llu)", azimuth_deg,
                    g + 1,
                    static_cast<unsigned long long>(options.generation.seed));
      source.label = label;
      if (generator_config.prior.condition_on_motion)
        source.label +=
            ", " + std::filesystem::path(generator_config.data.motions[motion])
                       .stem()
                       .string();
      source.open = [run_dir = args.run_dir, options] {
        return std::make_unique<GeneratedStream>(run_dir, options);
      };
      source.view_camera = view_camera;
      source.root_px = root_px;
      source.scale_px = scale_px;
      sources.push_back(std::move(source));
    }
  }
  return sources;
}

// A CSV field: quoted, with inner quotes doubled (labels hold commas).
std::string CsvQuoted(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text)
    quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// How a streamed rollout ended, in eval --frames' words: the stream
// running out is its clip's end; --seconds tracked, the time limit.
RolloutEnd StreamedRolloutEnd(const StreamedRollout& rollout, int max_steps) {
  if (rollout.diverged()) return RolloutEnd::kDiverged;
  if (rollout.stats().failed) return RolloutEnd::kEarlyExit;
  return rollout.stats().steps >= max_steps ? RolloutEnd::kTimeLimit
                                            : RolloutEnd::kClipEnd;
}

// The checkpoint's tracker along every stream of TrackedSources. Each
// starts where args.start says (by default the fit of the stream's first
// seconds: its first pose, seen by its first camera); the camera then
// dollies with the simulated character (the generator learned from cameras
// that followed the subject). A rollout succeeds when it tracks --seconds
// without an early exit. Prints a line per stream and the totals; draws
// the first with --video.
int RunTrackedGenerations(const GenerateArgs& args) {
  TorchPolicy policy(args.policy);
  const TrainConfig& config = policy.config();
  const auto character = LoadCharacterForSimulation(
      TrainedCharacterPath(config), config.data.scene, config.env.simulation);
  // Judged by the success rule (the worst keypoint within 100 px), not by
  // training's early exit, which may be stricter; no pushes.
  EvalOptions judged;
  judged.episode_s = args.seconds;
  const TrackingEnvOptions env_options = JudgedEnvOptions(config.env, judged);
  const int root = character->root_qpos_address();
  const int root_dof = character->root_dof_address();  // world-frame velocity
  const std::vector<TrackedSource> sources = TrackedSources(args);
  // The stream's first seconds as a user's clip.
  FitOptions fit_options =
      args.fit_config.empty() ? FitOptions() : ReadFitOptions(args.fit_config);
  fit_options.camera_motion = CameraMotion::kMoving;
  fit_options.fixed_focal_px = args.focal_px;
  fit_options.num_threads = 1;
  if (args.start_tilt == StartTilt::kView) {
    // Every azimuth's camera has --view's tilt.
    const Eigen::Vector2d pitch_roll_rad =
        CameraPitchRollRad(ViewCamera(args, args.view[0]));
    fit_options.tilt_known = true;
    fit_options.known_pitch_deg = pitch_roll_rad[0] * 180.0 / M_PI;
    fit_options.known_roll_deg = pitch_roll_rad[1] * 180.0 / M_PI;
  }
  fit_options.Validate();
  std::printf("tracking with %s: %zu stream(s) x %.0f s\n", args.policy.c_str(),
              sources.size(), args.seconds);
  if (args.start == GeneratedStart::kFit) {
    char tilt[96] = "tilt estimated";
    if (fit_options.tilt_known) {
      std::snprintf(tilt, sizeof(tilt),
                    "tilt --view's (pitch %.1f deg, roll %.1f deg)",
                    fit_options.known_pitch_deg, fit_options.known_roll_deg);
    }
    std::printf(
        "starts and cameras from the fit of each stream's first %.1f s "
        "(moving camera, focal %.0f px, %s, settings %s; no 3D), at %.1f s "
        "into it, the camera dollying with the character\n",
        args.start_fit_s, args.focal_px, tilt,
        args.fit_config.empty() ? "default" : args.fit_config.c_str(),
        StartAtS(args));
  } else {
    std::printf(
        "starts from the default pose placed under the first generated frame "
        "(no 3D), cameras the chosen view (elevation %.0f deg, %.1f m) "
        "dollying with the character\n",
        args.view[1], args.view[2]);
  }
  int succeeded = 0, rollouts = 0, unfitted = 0;
  double e2d_sum_px = 0.0;
  // --frames: a row per tracked frame of every rollout.
  const std::vector<std::string>& keypoint_names =
      character->keypoint_layout().keypoint_names;
  std::string frames_csv =
      "stream,label,start_frame,step,frame,keypoints_present,mean_px,"
      "worst_px,worst_keypoint,end\n";
  for (const TrackedSource& source : sources) {
    const int stream_index = static_cast<int>(&source - sources.data());
    // The start, its frame and the first camera.
    SimState start;
    int start_frame = 0;
    PinholeCamera first_camera = source.view_camera;
    if (args.start == GeneratedStart::kFit) {
      const Clip2D first_frames = FirstFramesOf(source, args.start_fit_s);
      ViewEstimate estimate;
      try {
        estimate = FitView(first_frames, *character, fit_options, source.label);
      } catch (const InputError& e) {
        // 2D a fit cannot use (a person leaving the image, a stream
        // shorter than the fitted seconds): that stream is lost, the
        // others still run.
        std::printf(
            "  fit of its first %d frames failed (%s): %s counted as "
            "lost\n",
            first_frames.num_frames(), e.what(), source.label.c_str());
        ++unfitted;
        continue;
      }
      // The fitted window's frame the rollout starts at.
      start_frame = std::min(
          first_frames.num_frames() - 1,
          static_cast<int>(std::lround(StartAtS(args) * first_frames.fps)));
      start = EstimatedState(character, config.env.simulation, estimate.poses,
                             start_frame);
      first_camera = estimate.CameraAt(start_frame);
      std::printf(
          "  fit of its first %d frames: %.1f px, %s\n",
          first_frames.num_frames(), estimate.summary.mean_reprojection_px,
          estimate.summary.converged() ? "every frame converged"
                                       : "some frames did not converge");
    } else {
      start = PlacedDefaultState(character, config.env.simulation,
                                 source.view_camera,
                                 {source.root_px, source.scale_px});
    }
    std::unique_ptr<ReferenceStream> stream = source.open();
    std::vector<Keypoint2D> skipped;
    for (int t = 0; t < start_frame; ++t) stream->Next(&skipped);
    StreamedRollout rollout(
        character, env_options, stream.get(),
        [&](int, const SimState& state, double lead_s) {
          // Where the character's root will be at the frame's time.
          return first_camera.Translated(
              {state.qpos[root] + state.qvel[root_dof] * lead_s -
                   start.qpos[root],
               state.qpos[root + 1] + state.qvel[root_dof + 1] * lead_s -
                   start.qpos[root + 1],
               0.0});
        },
        start);
    const bool draw = rollouts == 0 && !args.video.empty();
    std::vector<EpisodeFrame> frames;
    auto record = [&] {
      if (!draw) return;
      EpisodeFrame frame;
      frame.clip_frame = rollout.frame();
      frame.camera = rollout.camera();
      frame.reference = rollout.reference_frame();
      frame.state = rollout.simulation().Save();
      frames.push_back(std::move(frame));
    };
    record();
    // One CSV row for the step just taken (`last`: the rollout's end).
    const std::string quoted_label = CsvQuoted(source.label);
    auto record_frame = [&](bool last) {
      if (args.frames_csv.empty()) return;
      const ReprojectionError& error = rollout.last_error();
      char numbers[128];
      std::snprintf(numbers, sizeof(numbers), ",%d,%d,%d,%d,%.2f,%.2f,",
                    start_frame, rollout.stats().steps, rollout.frame(),
                    error.num_present, error.mean_px, error.max_px);
      const bool named =
          error.worst_keypoint >= 0 &&
          error.worst_keypoint < static_cast<int>(keypoint_names.size());
      frames_csv += std::to_string(stream_index) + "," + quoted_label +
                    numbers +
                    (named ? keypoint_names[error.worst_keypoint] : "") + "," +
                    (last ? RolloutEndName(StreamedRolloutEnd(
                                rollout, env_options.max_episode_steps()))
                          : "") +
                    "\n";
    };
    const auto started = std::chrono::steady_clock::now();
    while (rollout.Step(policy)) {
      record();
      record_frame(false);
    }
    record();
    if (rollout.stats().steps > 0) record_frame(true);
    const double wall_s = std::chrono::duration<double>(
                              std::chrono::steady_clock::now() - started)
                              .count();
    const EpisodeStats& stats = rollout.stats();
    ++rollouts;
    succeeded += stats.failed ? 0 : 1;
    e2d_sum_px += stats.mean_error_px();
    std::printf(
        "  %s: %s after %d of %d frames, E2D %.1f px, %.0fx real time\n",
        source.label.c_str(),
        stats.failed ? "lost (early exit)" : "tracked to the end", stats.steps,
        env_options.max_episode_steps(), stats.mean_error_px(),
        stats.steps / config.env.simulation.control_hz /
            std::max(1e-9, wall_s));
    std::fflush(stdout);
    if (!draw) continue;
    RecordedFrames recorded(std::move(frames));
    const Clip2D& format = stream->format();
    BundleReplayOptions replay;
    replay.output.video_path = args.video;
    EpisodeRenderOptions render;
    render.pose_label = "character (policy)";
    render.reference_label = args.real.empty() ? "generated 2D" : "real 2D";
    const EpisodeSummary summary =
        RenderViewFrames(recorded, character, config.env.simulation, format,
                         format.fps, render, replay);
    std::printf("  wrote %s (%d frames)\n", summary.video_path.c_str(),
                summary.frames_rendered);
  }
  // A stream whose start could not be fitted counts as lost; E2D is over
  // the rollouts that ran.
  const int total = rollouts + unfitted;
  std::printf("Succ %d/%d (%.0f %%), mean E2D %.1f px", succeeded, total,
              100.0 * succeeded / std::max(1, total),
              rollouts > 0 ? e2d_sum_px / rollouts : 0.0);
  if (unfitted > 0) std::printf(", %d not started (fit failed)", unfitted);
  std::printf("\n");
  if (!args.frames_csv.empty()) {
    WriteFileAtomic(args.frames_csv, frames_csv);
    std::printf("wrote %s (per-frame errors)\n", args.frames_csv.c_str());
  }
  return 0;
}

int RunGenerate(const GenerateArgs& args) {
  if (args.view.size() != 3)
    throw ConfigError("generate: --view takes azimuth,elevation,distance");
  if (args.policy.empty() &&
      (!args.video.empty() || !args.frames_csv.empty() ||
       args.generations != 1 || !args.azimuths_deg.empty() ||
       !args.real.empty() || args.each_motion))
    throw ConfigError(
        "generate: --video, --frames, --generations, --azimuths, --real and "
        "--each-motion need --policy");
  if (args.start_at_s >= 0.0 && args.start != GeneratedStart::kFit)
    throw ConfigError(
        "generate: --start-at-s needs --start fit (the fit's pose there)");
  if (!(StartAtS(args) < args.start_fit_s))
    throw ConfigError(
        "generate: --start-at-s must lie within the fitted --start-fit-s");
  if (!args.real.empty() && args.start != GeneratedStart::kFit)
    throw ConfigError(
        "generate: --real needs --start fit (a recorded view's 2D has no "
        "camera to place the default pose under)");
  // A prior conditioned on the view generates the data's view nearest to
  // --view.
  const GenConfig config = ReadPriorConfig(args.run_dir);
  GenerationOptions generation = args.generation;
  const int condition =
      GenerationView(config, args.view[0], args.view[1], args.motion);
  generation.view = condition;
  if (condition >= 0) {
    const int view = condition % config.prior_views();
    std::printf(
        "generating the data's view %d (azimuth %.0f deg, elevation "
        "%.0f deg), the nearest to --view%s%s\n",
        view, config.data.views.azimuth_deg(view),
        config.data.views.elevation_deg(view),
        config.prior.condition_on_motion ? ", of motion " : "",
        config.prior.condition_on_motion
            ? config.data.motions[args.motion].c_str()
            : "");
  }
  const GeneratedMotion motion =
      GenerateMotion(args.run_dir, args.seconds, generation);
  const int frames = motion.num_frames;
  const double fps = motion.fps;

  Eigen::Vector2d root_px;
  double scale_px = 0.0;
  StandingPlacement(ViewCamera(args, args.view[0]), &root_px, &scale_px);
  Clip2D clip = FromCanonical(CanonicalFromFeatures(
      motion.rows.data(), frames, Coco17Layout(), fps, root_px, scale_px));
  WriteClip(args.output, clip);
  std::printf(
      "wrote %s: %d frames at %.0f fps (%.1f s) from %d codes, generated in "
      "%.2f s (%.0fx real time)\n",
      args.output.c_str(), frames, fps, frames / fps, motion.num_codes,
      motion.generation_s, frames / fps / std::max(1e-9, motion.generation_s));
  if (args.policy.empty()) return 0;
  return RunTrackedGenerations(args);
}

struct GenEvalArgs {
  std::string run_dir;
  std::string output;
  // Real motion capture the generator never saw (Debian's
  // assimp-testmodels: CMU subject 1, playground).
  std::vector<std::string> held_apart = {
      "/usr/share/assimp/models/BVH/01_01.bvh",
      "/usr/share/assimp/models/BVH/01_03.bvh"};
  GeneratorEvalOptions options;
};

int RunGenEval(const GenEvalArgs& args) {
  const GenConfig config = ReadGeneratorConfig(args.run_dir);
  std::printf(
      "gen eval %s: %d generations x %.0f s; %d feature encoder(s) on %zu "
      "held-apart motions\n",
      args.run_dir.c_str(), args.options.generations, args.options.seconds,
      args.options.encoders, args.held_apart.size());
  std::fflush(stdout);
  const GenDataset real = LoadGenDataset(config, config.data.motions);
  const GenDataset held_apart = LoadGenDataset(config, args.held_apart);
  const GeneratorEvalResult result =
      EvaluateGenerator(args.run_dir, real, held_apart, args.options);
  std::printf("%s", result.BriefReport().c_str());
  if (!args.output.empty()) {
    nlohmann::json json = {
        {"run_dir", args.run_dir},
        {"generations", args.options.generations},
        {"seconds", args.options.seconds},
        {"temperature", args.options.generation.sampling.temperature},
        {"top_k", args.options.generation.sampling.top_k},
        {"kept_context_tokens",
         args.options.generation.sampling.kept_context_tokens},
        {"held_apart", args.held_apart},
        {"fid", result.fid},
        {"fid_floor_time", result.fid_floor_time},
        {"fid_floor_views", result.fid_floor_views},
        {"fid_floor_sampled", result.fid_floor_sampled},
        {"fid_floor_sampled_segment", result.fid_floor_sampled_segment},
        {"fid_reconstruction", result.fid_reconstruction},
        {"fid_stream_reconstruction", result.fid_stream_reconstruction},
        {"reconstruction_pose_error", result.reconstruction_pose_error},
        {"reconstruction_root_error", result.reconstruction_root_error},
        {"reconstruction_scale_error", result.reconstruction_scale_error},
        {"decode_context_codes",
         args.options.generation.decoding.context_codes},
        {"lookahead_codes", args.options.generation.decoding.lookahead_codes},
        {"emit_codes", args.options.generation.decoding.emit_codes},
        {"blend_seams", args.options.generation.decoding.blend_seams},
        {"placement_return_s", args.options.generation.placement_return_s},
        {"jump_threshold", result.jump_threshold},
        {"jumps_per_min_generated", result.jumps_per_min_generated},
        {"jumps_per_min_stream", result.jumps_per_min_stream},
        {"jumps_per_min_real", result.jumps_per_min_real},
        {"jump_share_at_seams", result.jump_share_at_seams},
        {"diversity_real", result.diversity_real},
        {"diversity_generated", result.diversity_generated},
        {"neighbours", args.options.neighbours},
        {"precision", result.precision},
        {"recall", result.recall},
        {"precision_floor_time", result.precision_floor_time},
        {"recall_floor_time", result.recall_floor_time},
        {"recall_by_motion", result.recall_by_motion},
        {"time_segments", args.options.time_segments},
        {"fid_by_time_segment", result.fid_by_time_segment},
        {"real_windows", result.real_windows},
        {"held_apart_windows", result.held_apart_windows},
        {"generated_windows", result.generated_windows},
        {"encoder_loss", result.encoder_loss},
        {"drift_log_scale_generated", result.drift_log_scale_generated},
        {"drift_log_scale_real", result.drift_log_scale_real},
        {"drift_root_generated", result.drift_root_generated},
        {"drift_root_real", result.drift_root_real},
        {"realtime_factor", result.realtime_factor}};
    json["encoders"] = args.options.encoders;
    json["encoder_seed"] = args.options.seed;
    for (const GeneratorFeatureFigures& figures : result.by_encoder) {
      json["fid_by_encoder"].push_back(figures.fid);
      json["fid_floor_time_by_encoder"].push_back(figures.fid_floor_time);
      json["encoder_loss_by_encoder"].push_back(figures.encoder_loss);
    }
    WriteFileAtomic(args.output, json.dump(2) + "\n");
  }
  return 0;
}

// The sampling and decoding flags `gen eval` and `generate` share.
void AddGenerationOptions(CLI::App* command, GenerationOptions* generation) {
  SamplingOptions* sampling = &generation->sampling;
  command->add_option("--temperature", sampling->temperature,
                      "Sampling temperature (> 0; lower is greedier)");
  command->add_option("--top-k", sampling->top_k,
                      "Sample among the k likeliest codes (0: all)");
  command->add_option(
      "--kept-context", sampling->kept_context_tokens,
      "Codes of the past the prior keeps in view when its full context "
      "slides (0: half the context)");
  command->add_option(
      "--placement-return", generation->placement_return_s,
      "Time constant (s) with which the stream's scale and root return "
      "toward their start, as the data's following cameras hold them "
      "(default 20; 0: off)");
  StreamDecoding* decoding = &generation->decoding;
  command->add_option("--decode-context", decoding->context_codes,
                      "Codes the streaming decoder sees per step");
  command->add_option("--lookahead", decoding->lookahead_codes,
                      "Codes decoded after the ones emitted (latency)");
  command->add_option("--emit-codes", decoding->emit_codes,
                      "Codes whose frames one decoding emits");
  command->add_option(
      "--blend-seams", decoding->blend_seams,
      "Fade each decoding's first frames in from what the previous one "
      "decoded for them (default true; false: the seams as decoded)");
}

}  // namespace

void AddGenCommands(CLI::App& app, CommandRun* run) {
  CLI::App* gen =
      app.add_subcommand("gen", "The 2D motion generator (VQ-VAE + GPT)");
  gen->require_subcommand(1);
  auto train_args = std::make_shared<GenTrainArgs>();
  CLI::App* train = gen->add_subcommand(
      "train", "Train the tokenizer, then the prior, from a YAML config");
  train
      ->add_option("config", train_args->config_path,
                   "Generator config (YAML), e.g. configs/gen/clips.yaml")
      ->check(CLI::ExistingFile);
  train->add_flag("--resume", train_args->resume,
                  "Continue from <run_dir>/tokenizer.pt and prior.pt");
  train->add_option("--run-dir", train_args->run_dir, "Override run.run_dir");
  train
      ->add_option("--tokenizer-steps", train_args->tokenizer_steps,
                   "Override tokenizer.steps (a quick try: a few hundred)")
      ->check(CLI::NonNegativeNumber);
  train
      ->add_option("--prior-steps", train_args->prior_steps,
                   "Override prior.steps")
      ->check(CLI::NonNegativeNumber);
  train->add_flag("--list-settings", train_args->list_settings,
                  "Print every config setting (Markdown) and exit");
  train->callback([run, train_args] {
    *run = [train_args] { return RunGenTrain(*train_args); };
  });

  auto eval_args = std::make_shared<GenEvalArgs>();
  CLI::App* eval = gen->add_subcommand(
      "eval",
      "FID of generated against real 2D motion (with the real-vs-real "
      "floors), diversity and generation speed");
  eval->add_option("run_dir", eval_args->run_dir,
                   "The generator's run folder (tokenizer.pt, prior.pt)")
      ->required()
      ->check(CLI::ExistingDirectory);
  eval->add_option("--generations", eval_args->options.generations,
                   "Independent generations (seeds 1..N)");
  eval->add_option("--seconds", eval_args->options.seconds,
                   "Length of each generation (s)");
  AddGenerationOptions(eval, &eval_args->options.generation);
  eval->add_option("--held-apart", eval_args->held_apart,
                   "Motions the feature encoder is trained on (never the "
                   "generator's)")
      ->delimiter(',');
  eval->add_option("--encoder-steps", eval_args->options.encoder_steps,
                   "Training steps of the feature encoder");
  eval->add_option("--encoders", eval_args->options.encoders,
                   "Feature encoders trained (seeds --encoder-seed on); "
                   "every feature figure is their mean")
      ->check(CLI::PositiveNumber);
  eval->add_option("--encoder-seed", eval_args->options.seed,
                   "Seed of the first feature encoder (and of the real "
                   "stretches the sampled floors draw)");
  eval->add_option("--time-segments", eval_args->options.time_segments,
                   "Also score each generation's k-th part of this many "
                   "alone (drift as the context slides)");
  eval->add_option("-o,--output", eval_args->output, "Figures as JSON")
      ->check(WritableFile());
  eval->callback([run, eval_args] {
    *run = [eval_args] { return RunGenEval(*eval_args); };
  });

  auto generate_args = std::make_shared<GenerateArgs>();
  CLI::App* generate = app.add_subcommand(
      "generate", "Generate 2D motion with a trained generator into a clip");
  generate
      ->add_option("run_dir", generate_args->run_dir,
                   "The generator's run folder (tokenizer.pt, prior.pt)")
      ->required()
      ->check(CLI::ExistingDirectory);
  generate
      ->add_option("-o,--output", generate_args->output, "Clip to write (JSON)")
      ->check(WritableFile())
      ->required();
  generate->add_option("--seconds", generate_args->seconds,
                       "Length of the generated motion (s)");
  generate->add_option("--seed", generate_args->generation.seed,
                       "Sampling seed");
  AddGenerationOptions(generate, &generate_args->generation);
  generate
      ->add_option("--view", generate_args->view,
                   "Camera azimuth (deg), elevation (deg), distance (m)")
      ->delimiter(',')
      ->expected(3);
  generate
      ->add_option("--motion", generate_args->motion,
                   "A prior conditioned on the motion (prior."
                   "condition_on_motion): which of its config's data.motions "
                   "to generate (from 0)")
      ->capture_default_str();
  generate->add_flag(
      "--each-motion", generate_args->each_motion,
      "With --policy and a prior conditioned on the motion: generation g "
      "draws the config's motion g mod their number (instead of --motion)");
  generate->add_option("--focal", generate_args->focal_px,
                       "Camera focal length (px)");
  generate
      ->add_option("--policy", generate_args->policy,
                   "A tracker checkpoint to drive along the generated 2D, "
                   "streamed frame by frame, the camera dollying with the "
                   "character")
      ->check(CLI::ExistingFile);
  generate
      ->add_option("--generations", generate_args->generations,
                   "With --policy: streams to track (seeds seed, seed+1, ...)")
      ->check(CLI::Range(1, 10000));
  generate
      ->add_option("--azimuths", generate_args->azimuths_deg,
                   "With --policy: camera azimuths (deg) to track each stream "
                   "from, at --view's elevation and distance (default: "
                   "--view's azimuth)")
      ->delimiter(',');
  generate->add_option("--video", generate_args->video,
                       "With --policy: the first tracked stream drawn (MP4)");
  generate
      ->add_option("--frames", generate_args->frames_csv,
                   "With --policy: every rollout's per-frame errors as CSV "
                   "(mean and worst keypoint in px, which keypoint, how the "
                   "rollout ended): where a stream starts to fail")
      ->check(WritableFile());
  generate
      ->add_option("--start", generate_args->start,
                   "With --policy: fit (the fit of each stream's first "
                   "--start-fit-s seconds gives the first pose and camera) "
                   "or default (the default pose under the --view camera)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, GeneratedStart>{
              {"fit", GeneratedStart::kFit},
              {"default", GeneratedStart::kDefault}},
          CLI::ignore_case));
  generate
      ->add_option("--real", generate_args->real,
                   "With --policy: track every view of this bundle's (or "
                   "clip's) 2D instead of generations, under the same "
                   "protocol (fitted start, following camera): the control")
      ->check(CLI::ExistingFile);
  generate
      ->add_option("--start-fit-s", generate_args->start_fit_s,
                   "With --start fit: seconds of each stream fitted")
      ->check(CLI::Range(0.5, 60.0));
  generate
      ->add_option("--start-tilt", generate_args->start_tilt,
                   "With --start fit: the start fit's camera pitch and roll: "
                   "view (--view's, held: the view is chosen, not filmed; "
                   "with --real, the recorded 2D's tilt said to be --view's) "
                   "or fit (estimated, as for a video; before 2026-12-07)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, StartTilt>{{"view", StartTilt::kView},
                                           {"fit", StartTilt::kFit}},
          CLI::ignore_case));
  generate
      ->add_option("--fit-config", generate_args->fit_config,
                   "With --start fit: FitOptions YAML for the fit of each "
                   "stream's first seconds (docs/fit.md, \"Settings\"), e.g. "
                   "the training fits' configs/fit/root_dolly.yaml; the "
                   "camera is moving and the focal --focal's")
      ->check(CLI::ExistingFile);
  generate
      ->add_option("--start-at-s", generate_args->start_at_s,
                   "With --start fit: start this far into the stream, from "
                   "the fit's pose there (an edge of the fitted window is "
                   "its least constrained frame; the prior's first codes "
                   "come from the start token alone; default: the middle "
                   "of the fitted seconds)")
      ->check(CLI::Range(0.0, 60.0));
  generate->callback([run, generate_args] {
    *run = [generate_args] { return RunGenerate(*generate_args); };
  });
}

}  // namespace m2d::cli
