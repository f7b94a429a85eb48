// cli: `mimic2d prior` — learns the fit's pose prior (a Gaussian mixture
// over the character's hinge angles, fit/pose_prior.h) from motion capture
// on the character's skeleton (docs/fit.md, "Pose prior").
#include <chrono>
#include <cstdio>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"
#include "fit/pose_prior_training.h"
#include "fit/retarget.h"
#include "motion/motion_io.h"
#include "sim/simulation.h"

namespace m2d::cli {
namespace {

struct PriorArgs {
  std::vector<std::string> motions;
  std::string output;
  std::string character = "characters/humanoid.yaml";
  PoseMixtureTrainingOptions options;
  double bvh_scale_m = 0.056444;  // metres per BVH unit (CMU / cgspeed)
};

int RunPrior(PriorArgs& args) {
  args.options.Validate();
  const std::string character_path = AssetArgumentPath(args.character);
  auto character =
      LoadCharacterForSimulation(character_path, "flat", SimulationOptions());
  const auto started = std::chrono::steady_clock::now();
  std::vector<Eigen::VectorXd> samples;
  std::vector<std::string> sources;
  for (const std::string& path : args.motions) {
    MotionSourceArgs source;
    source.path = path;
    source.skeleton = character->config().skeleton_path;
    source.bvh_scale_m = args.bvh_scale_m;
    source.fps = 30.0;
    const LoadedMotion loaded = LoadMotionSource(source);
    std::vector<Eigen::VectorXd> poses;
    if (loaded.motion.skeleton->name != character->skeleton().name) {
      // Another skeleton (a BVH capture): its COCO-17 points, fitted by the
      // character.
      std::vector<std::vector<Eigen::Vector3d>> points;
      for (int t = 0; t < loaded.motion.num_frames();
           t += args.options.frame_stride) {
        points.push_back(KeypointPositions(*loaded.motion.skeleton,
                                           loaded.keypoint_map,
                                           loaded.motion.frames[t]));
      }
      RetargetSummary retargeted;
      poses = RetargetKeypointsToHinges(*character, points, RetargetOptions(),
                                        path, &retargeted);
      std::printf(
          "%s: %zu poses retargeted (%.1f s at 30 Hz, one frame in %d; "
          "scale %.3f, keypoints %.1f cm off on average, %.1f at worst)\n",
          path.c_str(), poses.size(), loaded.motion.duration_s(),
          args.options.frame_stride, retargeted.scale,
          100 * retargeted.mean_error_m, 100 * retargeted.worst_frame_error_m);
    } else {
      poses = HingeAnglesOfMotion(*character, loaded.motion,
                                  args.options.frame_stride, path);
      std::printf("%s: %zu poses (%.1f s at 30 Hz, one frame in %d)\n",
                  path.c_str(), poses.size(), loaded.motion.duration_s(),
                  args.options.frame_stride);
    }
    samples.insert(samples.end(), poses.begin(), poses.end());
    sources.push_back(path.substr(path.find_last_of('/') + 1));
  }
  std::printf("fitting %d components to %zu poses of %d hinges (EM)...\n",
              args.options.num_components, samples.size(),
              character->num_actions());
  std::fflush(stdout);
  PoseMixtureTrainingSummary summary;
  PoseMixture mixture = TrainPoseMixture(*character, samples, args.options,
                                         "mimic2d prior", &summary);
  mixture.sources = sources;
  WritePoseMixtureAtomic(mixture, args.output);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started)
          .count();
  std::printf("%s, %.1f s\ncomponent weights:", summary.BriefReport().c_str(),
              seconds);
  for (double w : mixture.weights) std::printf(" %.3f", w);
  std::printf("\nwrote %s\n", args.output.c_str());
  return 0;
}

}  // namespace

void AddPriorCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<PriorArgs>();
  CLI::App* prior = app.add_subcommand(
      "prior",
      "Learn the fit's pose prior (a Gaussian mixture over the character's "
      "joint angles) from motion capture: DeepMimic files of its skeleton "
      "or CMU BVH captures");
  prior
      ->add_option("motions", args->motions,
                   "DeepMimic motion files of the character's skeleton "
                   "(.txt), or CMU BVH captures (.bvh, retargeted by their "
                   "COCO-17 points)")
      ->required()
      ->check(CLI::ExistingFile);
  prior->add_option("-o,--output", args->output, "the mixture (JSON)")
      ->check(WritableFile())
      ->required();
  prior
      ->add_option("--character", args->character,
                   "character config (relative to assets/ unless absolute)")
      ->default_val("characters/humanoid.yaml");
  prior
      ->add_option("--components", args->options.num_components,
                   "mixture components")
      ->default_val(args->options.num_components);
  prior
      ->add_option("--min-std", args->options.min_std_rad,
                   "added to every component's standard deviation (rad)")
      ->default_val(args->options.min_std_rad);
  prior
      ->add_option("--stride", args->options.frame_stride,
                   "use every n-th frame at 30 Hz")
      ->default_val(args->options.frame_stride);
  prior->add_option("--seed", args->options.seed, "EM's start")
      ->default_val(args->options.seed);
  prior->callback([run, args] { *run = [args] { return RunPrior(*args); }; });
}

}  // namespace m2d::cli
