// End-to-end checks of the `mimic2d` binary: real commands on real files,
// and every kind of bad input ending in a clear message and exit code 2.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"
#include "common/file_io.h"
#include "motion/bundle.h"
#include "motion/clip_io.h"
#include "motion/motion_io.h"
#include "synthetic_motion.h"
#include "test_paths.h"

namespace m2d {
namespace {

using testing::CommandResult;
using testing::RunMimic2d;

std::string WriteFile(const std::string& dir, const std::string& name,
                      const std::string& text) {
  std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Cli, HelpListsTheSubcommands) {
  CommandResult result = RunMimic2d("--help");
  EXPECT_EQ(result.exit_code, 0);
  for (const char* name :
       {"clip", "train", "eval", "render", "plot", "report", "bench", "demo"}) {
    EXPECT_NE(result.output.find(name), std::string::npos) << name;
  }
}

TEST(Cli, FromMotionWalkGivesFourViewsEqualToTheProjectedTruth) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  std::string dir = testing::TempDir("cli_walk");
  std::string bundle_path = dir + "/walk.json";
  CommandResult result =
      RunMimic2d("clip from-motion " + walk + " --views 4 -o " + bundle_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ReferenceBundle bundle = ReadBundle(bundle_path);
  ASSERT_EQ(bundle.views.size(), 4u);
  double worst = 0.0;
  for (const ReferenceView& view : bundle.views) {
    for (int t = 0; t < bundle.num_frames(); ++t) {
      for (int j = 0; j < 17; ++j) {
        Projection p =
            view.CameraAt(t).Project(bundle.ground_truth->keypoints_m[t][j]);
        worst = std::max(
            worst, (p.pixel_px - view.clip.keypoints.at(t, j).Pixel()).norm());
      }
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(RunMimic2d("clip info " + bundle_path).exit_code, 0);
}

TEST(Cli, BvhDemoMotionBecomesABundle) {
  const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  if (!std::ifstream(bvh))
    GTEST_FAIL() << bvh
                 << " absent (Debian assimp-testmodels, installed by setup.sh)";
  std::string dir = testing::TempDir("cli_bvh");
  CommandResult result = RunMimic2d(
      "clip from-motion " + bvh + " --views 2 --follow -o " + dir + "/b.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(ReadBundle(dir + "/b.json").views.size(), 2u);
}

// How many times `needle` occurs in `text`.
int CountOccurrences(const std::string& text, const std::string& needle) {
  int count = 0;
  for (size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size()))
    ++count;
  return count;
}

// `generate --policy`: a tracker driven along generated 2D streamed frame
// by frame (a tiny generator trained here, the committed walk2d tracker), a
// line per stream, the totals and the first stream drawn.
// A generator config small enough to train in a second (dir/tiny.yaml,
// run folder dir/gen): `motions` as a YAML list's items, `prior_extra`
// more lines of the prior section.
std::string WriteTinyGenConfig(const std::string& dir,
                               const std::string& motions,
                               const std::string& prior_extra) {
  return WriteFile(
      dir, "tiny.yaml",
      "data:\n  motions: [" + motions +
          "]\n  loop_to_s: 4\n  num_azimuths: 2\n  elevations_deg: [10]\n"
          "tokenizer:\n  num_codes: 16\n  code_size: 16\n  width: 32\n"
          "  residual_depth: 1\n  window_frames: 16\n  batch_size: 4\n"
          "  steps: 6\n"
          "prior:\n  num_layers: 1\n  num_heads: 2\n  embedding: 16\n"
          "  context_tokens: 8\n  batch_size: 4\n  steps: 4\n" +
          prior_extra + "run:\n  run_dir: " + dir +
          "/gen\n  torch_threads: 1\n");
}

TEST(Cli, GenerateDrivesATrackerAlongTheStream) {
  const std::string dir = testing::TempDir("cli_generate");
  const std::string config = WriteTinyGenConfig(
      dir, testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt"),
      "");
  CommandResult result = RunMimic2d("gen train " + config);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string policy =
      testing::SourcePath("assets/policies/walk2d/checkpoint.pt");
  result =
      RunMimic2d("generate " + dir + "/gen --seconds 2 --policy " + policy +
                 " --generations 2 --azimuths 30,120 --start-fit-s 1 --video " +
                 dir + "/tracked.mp4 --frames " + dir + "/frames.csv -o " +
                 dir + "/generated.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // --frames: a row per tracked frame of each of the 4 rollouts, as many
  // as its line says it tracked, the last naming how it ended.
  {
    std::ifstream csv(dir + "/frames.csv");
    std::string line;
    ASSERT_TRUE(std::getline(csv, line)) << "no " << dir << "/frames.csv";
    EXPECT_EQ(line,
              "stream,label,start_frame,step,frame,keypoints_present,mean_px,"
              "worst_px,worst_keypoint,end");
    std::map<int, int> rows_by_stream;
    std::map<int, std::string> last_row_by_stream;
    while (std::getline(csv, line)) {
      const int stream = std::stoi(line.substr(0, line.find(',')));
      ++rows_by_stream[stream];
      last_row_by_stream[stream] = line;
      // The label is quoted (it holds commas).
      EXPECT_NE(line.find(",\"azimuth "), std::string::npos) << line;
    }
    ASSERT_EQ(rows_by_stream.size(), 4u);
    int tracked_frames = 0;
    for (size_t at = result.output.find(" after "); at != std::string::npos;
         at = result.output.find(" after ", at + 1)) {
      if (std::isdigit(static_cast<unsigned char>(result.output[at + 7])))
        tracked_frames += std::stoi(result.output.substr(at + 7));
    }
    int rows = 0;
    for (const auto& [stream, count] : rows_by_stream) rows += count;
    EXPECT_EQ(rows, tracked_frames) << result.output;
    for (const auto& [stream, row] : last_row_by_stream) {
      const std::string end = row.substr(row.rfind(',') + 1);
      EXPECT_TRUE(end == "time_limit" || end == "early_exit" ||
                  end == "clip_end" || end == "diverged")
          << row;
    }
  }
  EXPECT_NE(result.output.find("wrote " + dir + "/frames.csv"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("azimuth 120 deg, generation 2 (seed 2): "),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("Succ "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("/4 ("), std::string::npos) << result.output;
  EXPECT_GT(std::filesystem::file_size(dir + "/tracked.mp4"), 1000u);
  EXPECT_EQ(ReadClip(dir + "/generated.json").num_frames(), 60);
  // By default each rollout starts from the fit of its stream's first
  // seconds: a line per rollout says how the fit went, or why it failed.
  EXPECT_NE(result.output.find("starts and cameras from the fit"),
            std::string::npos)
      << result.output;
  EXPECT_EQ(CountOccurrences(result.output, "fit of its first 30 frames"), 4)
      << result.output;
  // and starts in the middle of the fitted seconds; the generated view's
  // tilt (--view's default elevation 10 deg) is held in that fit.
  EXPECT_NE(result.output.find("at 0.5 s into it"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("tilt --view's (pitch 10.0 deg, roll 0.0 deg)"),
            std::string::npos)
      << result.output;
  result = RunMimic2d("generate " + dir + "/gen --seconds 2 --policy " +
                      policy + " --start default --start-fit-s 1 -o " + dir +
                      "/default.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("starts from the default pose"),
            std::string::npos)
      << result.output;
  EXPECT_EQ(result.output.find("fit of its first"), std::string::npos)
      << result.output;

  // --real: the same protocol on a recorded walk's 2D (a dolly on the root,
  // as the rollout's camera follows the character), the control the
  // generated figures are read against: the walk2d tracker follows it.
  result = RunMimic2d(
      "clip from-motion " +
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt") +
      " --views 2 --duration 4 --follow --follow-smoothing 0 -o " + dir +
      "/real.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunMimic2d("generate " + dir + "/gen --seconds 3 --policy " +
                      policy + " --real " + dir +
                      "/real.json --start-at-s 0.5 --start-tilt fit "
                      "--fit-config " +
                      testing::SourcePath("configs/fit/root_dolly.yaml") +
                      " -o " + dir + "/unused.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // The start's fit with the settings for a camera on the root.
  EXPECT_NE(
      result.output.find("settings " +
                         testing::SourcePath("configs/fit/root_dolly.yaml")),
      std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("tilt estimated"), std::string::npos)
      << result.output;
  EXPECT_EQ(CountOccurrences(result.output, "tracked to the end"), 2)
      << result.output;
  EXPECT_NE(result.output.find("Succ 2/2"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("at 0.5 s into it"), std::string::npos)
      << result.output;
  // The start lies within the fitted seconds.
  result =
      RunMimic2d("generate " + dir + "/gen --policy " + policy +
                 " --start-fit-s 1 --start-at-s 1 -o " + dir + "/unused.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("within the fitted --start-fit-s"),
            std::string::npos)
      << result.output;
  // A recorded view has no camera to place the default pose under.
  result =
      RunMimic2d("generate " + dir + "/gen --policy " + policy + " --real " +
                 dir + "/real.json --start default -o " + dir + "/unused.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--real needs --start fit"), std::string::npos)
      << result.output;
  // The tracking options need a tracker.
  result = RunMimic2d("generate " + dir + "/gen --video " + dir + "/x.mp4 -o " +
                      dir + "/x.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("need --policy"), std::string::npos)
      << result.output;
  result = RunMimic2d("generate " + dir + "/gen --real " + dir +
                      "/real.json -o " + dir + "/x.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("need --policy"), std::string::npos)
      << result.output;
  result = RunMimic2d("generate " + dir + "/gen --each-motion -o " + dir +
                      "/x.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("need --policy"), std::string::npos)
      << result.output;
}

// A prior conditioned on the motion: `generate --policy --each-motion`
// spreads the tracked generations over the config's motions (generation g
// draws motion g mod their number) and names each stream's motion.
TEST(Cli, GenEvalReadsItsFiguresInSeveralEncoders) {
  // `gen eval --encoders 2`: each encoder's FID and floor in the JSON, the
  // FID their mean, each one's ratio printed; no encoder is refused.
  const std::string dir = testing::TempDir("cli_gen_eval");
  const std::string config = WriteTinyGenConfig(
      dir, testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt"),
      "");
  // Real sequences of 6 s: their halves in time hold a 64-frame window.
  std::string text = ReadFileText(config);
  text.replace(text.find("loop_to_s: 4"), 12, "loop_to_s: 6");
  WriteFileAtomic(config, text);
  CommandResult result = RunMimic2d("gen train " + config);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string json_path = dir + "/eval.json";
  const std::string eval = "gen eval " + dir +
                           "/gen --generations 2 --seconds 4 "
                           "--encoder-steps 10 --time-segments 1 ";
  result = RunMimic2d(eval + "--encoders 2 -o " + json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("feature encoders 2"), std::string::npos)
      << result.output;
  const nlohmann::json figures = ReadJsonFile(json_path);
  ASSERT_EQ(figures.at("fid_by_encoder").size(), 2u);
  ASSERT_EQ(figures.at("fid_floor_time_by_encoder").size(), 2u);
  EXPECT_EQ(figures.at("encoders"), 2);
  EXPECT_NEAR(figures.at("fid").get<double>(),
              0.5 * (figures.at("fid_by_encoder")[0].get<double>() +
                     figures.at("fid_by_encoder")[1].get<double>()),
              1e-9);
  result = RunMimic2d(eval + "--encoders 0");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--encoders"), std::string::npos)
      << result.output;
}

TEST(Cli, GenerateEachMotionSpreadsTrackedStreamsOverTheMotions) {
  const std::string dir = testing::TempDir("cli_generate_each_motion");
  const std::string config = WriteTinyGenConfig(
      dir,
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt") +
          ", " +
          testing::SourcePath("assets/motions/deepmimic/humanoid3d_run.txt"),
      "  condition_on_view: true\n  condition_on_motion: true\n");
  CommandResult result = RunMimic2d("gen train " + config);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string policy =
      testing::SourcePath("assets/policies/walk2d/checkpoint.pt");
  result =
      RunMimic2d("generate " + dir + "/gen --seconds 1 --policy " + policy +
                 " --generations 3 --each-motion --start-fit-s 1 -o " + dir +
                 "/generated.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("generation 1 (seed 1), humanoid3d_walk: "),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("generation 2 (seed 2), humanoid3d_run: "),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("generation 3 (seed 3), humanoid3d_walk: "),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("/3 ("), std::string::npos) << result.output;
}

// Each bad input: exit code 2, one line naming the file and the problem.
void ExpectInputError(const std::string& arguments, const std::string& file,
                      const std::string& problem) {
  CommandResult result = RunMimic2d(arguments);
  EXPECT_EQ(result.exit_code, 2) << arguments << "\n" << result.output;
  EXPECT_NE(result.output.find("error: "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find(file), std::string::npos) << result.output;
  EXPECT_NE(result.output.find(problem), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("terminate called"), std::string::npos)
      << result.output;
}

// `--character` reads a DeepMimic file with a character's skeleton and
// keypoint map: two frames of the dog at rest, written here in DeepMimic's
// format (the dog3d clips stay in ../shared), become AP-10K keypoints.
TEST(Cli, ADogMotionBecomesABundleOfAnimalKeypoints) {
  const std::string dir = testing::TempDir("cli_dog");
  // Per frame: duration, root position and rotation, 18 ball joints'
  // quaternions, 4 elbow and knee angles (Y up, as DeepMimic writes).
  std::string frame = "[0.0333, 0, 0.6, 0, 1, 0, 0, 0";
  for (int j = 0; j < 18; ++j) frame += ", 1, 0, 0, 0";
  frame += ", 0.5, 0.5, -0.5, -0.5]";
  const std::string motion = WriteFile(
      dir, "dog.txt",
      R"({"Loop": "none", "Frames": [)" + frame + ", " + frame + "]}");
  CommandResult result = RunMimic2d("clip from-motion " + motion +
                                    " --character characters/dog.yaml --views 2"
                                    " -o " +
                                    dir + "/dog.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const ReferenceBundle bundle = ReadBundle(dir + "/dog.json");
  EXPECT_EQ(bundle.views[0].clip.layout->name, "ap10k");
  EXPECT_EQ(bundle.ground_truth->skeleton_name, "dog");
  // The humanoid's skeleton cannot read it, and says why.
  ExpectInputError("clip from-motion " + motion + " -o " + dir + "/h.json",
                   motion, "needs 44");
  // A BVH file carries its own skeleton.
  const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  ExpectInputError("clip from-motion " + bvh +
                       " --character characters/dog.yaml -o " + dir + "/b.json",
                   bvh, "carries its own skeleton");
}

// `--ball auto` puts a ball in the walk's path, simulates its kick with the
// walk replayed, and projects it; the fit places it under its cameras, and
// `fit --truth` measures how far off that is.
TEST(Cli, AKickedBallIsSimulatedProjectedAndFitted) {
  const std::string dir = testing::TempDir("cli_ball");
  const std::string walk =
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt");
  CommandResult result = RunMimic2d(
      "clip from-motion " + walk +
      " --ball auto --duration 2 --views 1 --distance 6 --aim middle -o " +
      dir + "/truth.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("ball: placed at"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("ball: kicked at frame"), std::string::npos)
      << result.output;
  const ReferenceBundle truth = ReadBundle(dir + "/truth.json");
  ASSERT_EQ(truth.ground_truth->objects.size(), 1u);
  const std::vector<Eigen::Vector3d>& ball =
      truth.ground_truth->objects[0].positions_m;
  EXPECT_GT((ball.back() - ball.front()).norm(), 1.0);  // it was kicked
  ASSERT_EQ(truth.views[0].clip.objects.size(), 1u);
  result = RunMimic2d("clip info " + dir + "/truth.json");
  EXPECT_NE(result.output.find("object: ball, seen in"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("3D: ground truth"), std::string::npos)
      << result.output;

  ASSERT_EQ(
      RunMimic2d("clip strip " + dir + "/truth.json -o " + dir + "/2d.json")
          .exit_code,
      0);
  result = RunMimic2d("fit " + dir + "/2d.json --focal 1000 --quiet --truth " +
                      dir + "/truth.json -o " + dir + "/fitted.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const ReferenceBundle fitted = ReadBundle(dir + "/fitted.json");
  ASSERT_EQ((*fitted.estimate)[0].objects.size(), 1u);
  // The ball's offset from the walker, against the truth's: exact where it
  // rolls in view; off during its 20 cm hop off the foot and once it has
  // left the image (then it rolls on by the model). Measured 2026-11-30:
  // 175 mm; placed in a wrong world it would be metres off.
  const size_t at = result.output.find(", object ");
  ASSERT_NE(at, std::string::npos) << result.output;
  EXPECT_LT(std::stod(result.output.substr(at + 9)), 300.0) << result.output;

  // Where no foot passes, nothing kicks it: a named error.
  ExpectInputError(
      "clip from-motion " + walk + " --ball 20,20 -o " + dir + "/x.json", walk,
      "is never kicked");
  ExpectInputError(
      "clip from-motion " + walk + " --ball left -o " + dir + "/x.json",
      "--ball", "neither auto nor X,Y");
  const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  ExpectInputError(
      "clip from-motion " + bvh + " --ball auto -o " + dir + "/b.json", bvh,
      "not in its skeleton");
}

// `clip strip` leaves what a user with videos has: the 2D, no truth, no
// cameras, no estimate; `clip info` says so.
// `bench env --torque-limit pd`: the environment under the PD limit, its
// replay checked against Simulation::Step; a bad value is named.
TEST(Cli, BenchEnvRunsUnderEitherTorqueLimit) {
  CommandResult pd = RunMimic2d(
      "bench env --threads-max 1 --repeats 1 --seconds 0.05 --warmup 5 "
      "--torque-limit pd");
  ASSERT_EQ(pd.exit_code, 0) << pd.output;
  EXPECT_NE(pd.output.find("torque_limit pd"), std::string::npos) << pd.output;
  // Identical trajectories up to the last bits (as under servo, 1e-15).
  const std::string check = "replay check: worlds end within ";
  const size_t at = pd.output.find(check);
  ASSERT_NE(at, std::string::npos) << pd.output;
  EXPECT_LT(std::stod(pd.output.substr(at + check.size())), 1e-9) << pd.output;
  CommandResult bad = RunMimic2d("bench env --torque-limit total");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--torque-limit"), std::string::npos) << bad.output;
}

// The cells of the row named `name` in a `clip feasibility` table.
std::vector<std::string> FeasibilityRow(const std::string& output,
                                        const std::string& name) {
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream cells(line);
    std::vector<std::string> row;
    for (std::string cell; cells >> cell;) row.push_back(cell);
    if (!row.empty() && row[0] == name) return row;
  }
  return {};
}

// `clip feasibility` on the repository's walk: the truth within the PD
// limits and past the servo limits in some frames; each view's estimate
// (the truth turned and moved: the same motion) reads as the truth does;
// every frame in the CSV; named errors for a bundle without an estimate
// and for another character's skeleton.
TEST(Cli, ClipFeasibilityMeasuresTheTruthAndEachViewsFit) {
  const std::string dir = testing::TempDir("cli_feasibility");
  const std::string walk = dir + "/walk.json";
  CommandResult made = RunMimic2d(
      "clip from-motion " +
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt") +
      " --views 2 --duration 2 -o " + walk);
  ASSERT_EQ(made.exit_code, 0) << made.output;

  const std::string csv = dir + "/frames.csv";
  CommandResult pd = RunMimic2d("clip feasibility " + walk +
                                " --torque-limit pd --frames " + csv);
  ASSERT_EQ(pd.exit_code, 0) << pd.output;
  const std::vector<std::string> pd_truth = FeasibilityRow(pd.output, "truth");
  ASSERT_GE(pd_truth.size(), 7u) << pd.output;
  EXPECT_EQ(pd_truth[2], "0.0%") << pd.output;  // over a torque limit
  CommandResult servo = RunMimic2d("clip feasibility " + walk);
  ASSERT_EQ(servo.exit_code, 0) << servo.output;
  const std::vector<std::string> servo_truth =
      FeasibilityRow(servo.output, "truth");
  ASSERT_GE(servo_truth.size(), 7u) << servo.output;
  EXPECT_GT(std::stod(servo_truth[2]), 5.0) << servo.output;

  const ReferenceBundle bundle = ReadBundle(walk);
  std::ifstream frames(csv);
  std::string line;
  int lines = 0;
  std::getline(frames, line);
  EXPECT_EQ(line.rfind("poses,frame,touching,worst_torque_ratio", 0), 0u);
  while (std::getline(frames, line)) ++lines;
  EXPECT_EQ(lines, bundle.num_frames());

  CommandResult no_estimate =
      RunMimic2d("clip feasibility " + walk + " --poses estimate");
  EXPECT_NE(no_estimate.exit_code, 0);
  EXPECT_NE(no_estimate.output.find("has no estimate"), std::string::npos)
      << no_estimate.output;

  ReferenceBundle fitted = bundle;
  fitted.estimate =
      testing::EstimateFromTruth(bundle, {{0.0, {0, 0, 0}}, {1.2, {3, -1, 0}}});
  const std::string fitted_path = dir + "/fitted.json";
  WriteBundle(fitted_path, fitted);
  CommandResult views =
      RunMimic2d("clip feasibility " + fitted_path + " --poses estimate");
  ASSERT_EQ(views.exit_code, 0) << views.output;
  for (const ReferenceView& view : bundle.views) {
    const std::vector<std::string> row =
        FeasibilityRow(views.output, view.name);
    ASSERT_GE(row.size(), 7u) << views.output;
    for (int cell = 1; cell <= 6; ++cell) {
      EXPECT_EQ(row[cell], servo_truth[cell]) << view.name << " " << cell;
    }
  }

  CommandResult dog = RunMimic2d("clip feasibility " + walk +
                                 " --character characters/dog.yaml");
  EXPECT_NE(dog.exit_code, 0);
  EXPECT_NE(dog.output.find("poses are of skeleton"), std::string::npos)
      << dog.output;
}

TEST(Cli, ClipStripKeepsOnlyThe2D) {
  const std::string dir = testing::TempDir("cli_strip");
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(testing::SourcePath("assets/skeletons/humanoid.yaml")));
  KeypointMap map = LoadKeypointMap(
      testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"), *skeleton);
  BundleFromMotionOptions options;
  options.rig.num_views = 3;
  options.follow = CameraFollow::kRootDolly;
  ReferenceBundle bundle = MakeBundleFromMotion(
      testing::GlidingMotion(skeleton, testing::IdentityPose(*skeleton), 1.0),
      map, options, "gliding");
  bundle.estimate = testing::EstimateFromTruth(bundle, {{0.3, {1, 1, 0}}});
  const std::string full = dir + "/full.json";
  const std::string stripped_path = dir + "/stripped.json";
  WriteBundle(full, bundle);
  CommandResult info = RunMimic2d("clip info " + full);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("true cameras: every view"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("estimate: every view"), std::string::npos)
      << info.output;

  CommandResult result =
      RunMimic2d("clip strip " + full + " -o " + stripped_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ReferenceBundle stripped = ReadBundle(stripped_path);
  EXPECT_FALSE(stripped.ground_truth.has_value());
  EXPECT_FALSE(stripped.estimate.has_value());
  EXPECT_EQ(stripped.name, "gliding");
  EXPECT_EQ(stripped.fps, bundle.fps);
  ASSERT_EQ(stripped.views.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(stripped.views[k].cameras.empty());
    EXPECT_EQ(stripped.views[k].name, bundle.views[k].name);
    const Clip2D& clip = stripped.views[k].clip;
    EXPECT_EQ(clip.image_width_px, bundle.views[k].clip.image_width_px);
    EXPECT_EQ(clip.image_height_px, bundle.views[k].clip.image_height_px);
    ASSERT_EQ(clip.num_frames(), bundle.num_frames());
    for (int t = 0; t < clip.num_frames(); ++t) {
      for (int j = 0; j < 17; ++j) {
        EXPECT_NEAR((clip.keypoints.at(t, j).Pixel() -
                     bundle.views[k].clip.keypoints.at(t, j).Pixel())
                        .norm(),
                    0.0, 1e-9);
      }
    }
  }
  info = RunMimic2d("clip info " + stripped_path);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("ground truth: none"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("true cameras: none"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("estimate: none"), std::string::npos)
      << info.output;
  ExpectInputError("clip strip " + dir + "/absent.json -o " + dir + "/x.json",
                   dir + "/absent.json", "cannot open");
  // A stripped bundle has nothing to replay: no truth, no fit yet.
  ExpectInputError("render " + stripped_path + " -o " + dir + "/x.mp4",
                   stripped_path, "no true cameras");
  ExpectInputError(
      "render " + stripped_path + " --estimate -o " + dir + "/x.mp4",
      stripped_path, "has no estimate to replay");

  // Eval of the committed walk policy from the estimate alone, measured
  // against the truth kept in the original file.
  const std::string policy =
      testing::SourcePath("assets/policies/walk/checkpoint.pt");
  ReferenceBundle fitted = StripBundle(bundle);
  fitted.estimate = bundle.estimate;
  const std::string fitted_path = dir + "/fitted.json";
  WriteBundle(fitted_path, fitted);
  const std::string json_path = dir + "/eval.json";
  result = RunMimic2d("eval " + policy + " --bundle " + full +
                      " --starts estimate --cameras estimate --episodes 1 "
                      "--episode-s 0.3 -o " +
                      json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("initial states from the fitted estimate"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("E3DPA(mm)"), std::string::npos)
      << result.output;
  nlohmann::json eval = ReadJsonFile(json_path);
  EXPECT_EQ(eval["starts"], "estimate");
  EXPECT_EQ(eval["cameras"], "estimate");
  EXPECT_TRUE(eval["all"]["e3d_mm"].is_null());  // worlds differ
  EXPECT_TRUE(eval["all"]["e3d_pa_mm"].is_number());
  EXPECT_EQ(eval["camera"], "recorded");  // the checkpoint's env.camera
  // --camera: the episodes' camera, said in the header and the JSON.
  const std::string following_json = dir + "/eval_following.json";
  result = RunMimic2d("eval " + policy + " --bundle " + full +
                      " --starts estimate --cameras estimate --camera "
                      "follows_character --episodes 1 --episode-s 0.3 -o " +
                      following_json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("the cameras follow the character"),
            std::string::npos)
      << result.output;
  EXPECT_EQ(ReadJsonFile(following_json)["camera"], "follows_character");
  result = RunMimic2d("eval " + policy + " --bundle " + full +
                      " --camera sideways --episodes 1");
  EXPECT_NE(result.exit_code, 0) << result.output;  // CLI11's validation
  EXPECT_NE(result.output.find("--camera: sideways not in"), std::string::npos)
      << result.output;
  // The stripped-and-fitted file measured against the original's truth
  // (--truth) gives the same figures: the rollouts never read it.
  const std::string stripped_json = dir + "/eval_stripped.json";
  const std::string frames_csv = dir + "/frames/eval_frames.csv";
  result = RunMimic2d("eval " + policy + " --bundle " + fitted_path +
                      " --truth " + full +
                      " --starts estimate --cameras estimate --episodes 1 "
                      "--episode-s 0.3 -o " +
                      stripped_json + " --frames " + frames_csv);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("rollouts ended: "), std::string::npos)
      << result.output;
  nlohmann::json measured = ReadJsonFile(stripped_json);
  // --frames: one CSV line per simulated step of every rollout, the worst
  // keypoint named, PA-MPJPE from the hidden truth, the end on the last.
  {
    std::ifstream csv(frames_csv);
    std::string line;
    ASSERT_TRUE(std::getline(csv, line)) << frames_csv;
    EXPECT_EQ(line,
              "clip,view,rollout,start_frame,step,frame,keypoints_present,"
              "mean_px,worst_px,worst_keypoint,worst_view,pa_mm,end");
    int lines = 0, ends = 0;
    while (std::getline(csv, line)) {
      ++lines;
      std::vector<std::string> cells;
      std::istringstream fields(line + ",");
      for (std::string cell; std::getline(fields, cell, ',');)
        cells.push_back(cell);
      ASSERT_EQ(cells.size(), 13u) << line;
      EXPECT_EQ(cells[0], fitted.name) << line;
      EXPECT_EQ(cells[9].find_first_not_of("abcdefghijklmnopqrstuvwxyz_"),
                std::string::npos)
          << line;
      EXPECT_FALSE(cells[9].empty()) << line;
      EXPECT_EQ(cells[10], cells[1]) << line;  // one view at a time
      EXPECT_GT(std::stod(cells[11]), 0.0) << line;
      if (!cells[12].empty()) ++ends;
    }
    int frames = 0, rollouts = 0;
    for (const auto& row : measured["rows"]) {
      for (const auto& rollout : row["rollouts"]) {
        frames += rollout["frames"].get<int>();
        ++rollouts;
        EXPECT_TRUE(rollout["end"].is_string());
      }
    }
    EXPECT_EQ(lines, frames);
    EXPECT_EQ(ends, rollouts);
    EXPECT_EQ(rollouts, 3);
  }
  ASSERT_TRUE(measured["all"]["e3d_root_mm"].is_number());
  EXPECT_DOUBLE_EQ(measured["all"]["e3d_root_mm"].get<double>(),
                   eval["all"]["e3d_root_mm"].get<double>());
  EXPECT_DOUBLE_EQ(measured["all"]["e3d_pa_mm"].get<double>(),
                   eval["all"]["e3d_pa_mm"].get<double>());
  ExpectInputError("eval " + policy + " --bundle " + fitted_path + " --truth " +
                       stripped_path +
                       " --starts estimate --cameras estimate --episodes 1",
                   stripped_path, "no ground_truth section");
  result = RunMimic2d("eval " + policy + " --bundle " + fitted_path +
                      " --truth " + full + " --truth " + full +
                      " --starts estimate --cameras estimate --episodes 1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("give one per --bundle"), std::string::npos)
      << result.output;
  // --asi-starts needs buffers known to belong to these bundles; the
  // committed walk checkpoint predates the fingerprint.
  ExpectInputError("eval " + policy + " --bundle " + full +
                       " --asi-starts --episodes 1 --episode-s 0.3",
                   policy, "initial-state buffers");
  // Truth sources on the stripped file: a named error, not a crash.
  ExpectInputError(
      "eval " + policy + " --bundle " + fitted_path + " --episodes 1",
      fitted_path, "initial_states: truth needs ground-truth");
  ExpectInputError("eval " + policy + " --bundle " + fitted_path +
                       " --starts default --episodes 1",
                   fitted_path, "stripped? use cameras: estimate");
}

// `mimic2d prior` learns a mixture from a DeepMimic clip of the humanoid's
// own skeleton and a CMU capture retargeted by its COCO-17 points, and names
// a file that is neither.
TEST(Cli, PriorLearnsFromOwnAndRetargetedMotion) {
  const std::string dir = testing::TempDir("cli_prior");
  const std::string output = dir + "/prior.json";
  CommandResult result = RunMimic2d(
      "prior " +
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt") +
      " /usr/share/assimp/models/BVH/01_01.bvh --components 2 -o " + output);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("01_01.bvh: "), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("retargeted"), std::string::npos)
      << result.output;
  const nlohmann::json mixture = ReadJsonFile(output);
  EXPECT_EQ(mixture["components"].size(), 2u);
  ASSERT_EQ(mixture["sources"].size(), 2u);
  EXPECT_EQ(mixture["sources"][0], "humanoid3d_walk.txt");
  EXPECT_EQ(mixture["sources"][1], "01_01.bvh");
  const std::string not_motion = WriteFile(dir, "notes.txt", "hello");
  ExpectInputError("prior " + not_motion + " -o " + dir + "/x.json", not_motion,
                   "");
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.json"));
}

TEST(Cli, BadInputIsAClearErrorNotACrash) {
  std::string dir = testing::TempDir("cli_bad");
  std::string malformed =
      WriteFile(dir, "malformed.json", "{\"format\": \"mimic2d.clip\", ");
  ExpectInputError("clip info " + malformed, malformed, "malformed JSON");

  std::string layout = WriteFile(
      dir, "layout.json",
      R"({"format": "mimic2d.clip", "version": 1, "layout": "coco99", "fps": 30,
          "image_width_px": 100, "image_height_px": 100, "keypoints": [[[1, 2, 1]]]})");
  ExpectInputError("clip info " + layout, layout, "coco99");

  std::string nan_point = WriteFile(
      dir, "nan.json",
      R"({"format": "mimic2d.clip", "version": 1, "layout": "point", "fps": 30,
          "image_width_px": 100, "image_height_px": 100, "keypoints": [[[null, 2, 0.9]]]})");
  ExpectInputError("clip info " + nan_point, nan_point, "frame 0");

  std::string empty = WriteFile(
      dir, "empty.json",
      R"({"format": "mimic2d.clip", "version": 1, "layout": "coco17", "fps": 30,
          "image_width_px": 100, "image_height_px": 100, "keypoints": []})");
  ExpectInputError("clip info " + empty, empty, "no frames");

  std::string shape = WriteFile(
      dir, "shape.json",
      R"({"format": "mimic2d.clip", "version": 1, "layout": "point", "fps": 30,
          "image_width_px": 100, "image_height_px": 100, "keypoints": [[[1, 2, 1], [3, 4, 1]]]})");
  ExpectInputError("clip info " + shape, shape, "2 keypoints");

  std::string short_bvh =
      WriteFile(dir, "short.bvh",
                "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 "
                "Xposition Yposition Zposition "
                "Zrotation Yrotation Xrotation\n  End Site\n  {\n    OFFSET 0 "
                "1 0\n  }\n}\nMOTION\n"
                "Frames: 2\nFrame Time: 0.0333\n0 0 0 0 0 0\n0 0 0 0\n");
  ExpectInputError("clip from-motion " + short_bvh + " -o " + dir + "/out.json",
                   short_bvh, "frame");

  std::string motion = WriteFile(
      dir, "motion.txt", "{\"Loop\": \"wrap\", \"Frames\": [[0.03, 0, 1]]}");
  ExpectInputError("clip from-motion " + motion + " -o " + dir + "/out.json",
                   motion, "needs 44");

  ExpectInputError("clip info " + dir + "/absent.json", dir + "/absent.json",
                   "cannot open");

  // A file that is not a training checkpoint, to every checkpoint command.
  ExpectInputError("checkpoint info " + malformed, malformed,
                   "not a mimic2d checkpoint");
  ExpectInputError("checkpoint slim " + malformed + " -o " + dir + "/out.pt",
                   malformed, "not a mimic2d checkpoint");
  ExpectInputError("checkpoint average " + malformed + " " + malformed +
                       " -o " + dir + "/out.pt",
                   malformed, "not a mimic2d checkpoint");
  // One checkpoint is nothing to average: a usage error.
  const CommandResult one_input =
      RunMimic2d("checkpoint average " + malformed + " -o " + dir + "/out.pt");
  EXPECT_NE(one_input.exit_code, 0);
  EXPECT_NE(one_input.output.find("checkpoints"), std::string::npos)
      << one_input.output;
  EXPECT_FALSE(std::ifstream(dir + "/out.pt").good());
  EXPECT_FALSE(
      std::ifstream(dir + "/out.json").good());  // nothing half-written
}

TEST(Cli, BadSettingsAreRejected) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  CommandResult result =
      RunMimic2d("clip from-motion " + walk + " --views 0 -o /tmp/never.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("num_views"), std::string::npos)
      << result.output;
  // Found by fuzzing: an abort from running out of memory.
  result = RunMimic2d("clip from-motion " + walk +
                      " --views 100000 -o /tmp/never.json");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("num_views must be in [1, 256]"),
            std::string::npos)
      << result.output;
}

// An output that cannot be written is refused when the command line is
// read (CLI11's validation error, exit 105), before the work: a folder
// given as the file, or a "folder" that is a file. Missing folders are
// fine, relative (from the working directory) or absolute.
TEST(Cli, OutputsThatCannotBeWrittenAreRefusedBeforeAnyWork) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  const std::string dir = testing::TempDir("cli_outputs");
  const std::string file = WriteFile(dir, "plain.txt", "not a folder");
  const std::string model =
      std::string(MIMIC2D_SOURCE_DIR) + "/assets/policies/walk2d/checkpoint.pt";
  struct Refused {
    std::string arguments, path, problem;
  };
  const std::vector<Refused> refused = {
      {"eval " + model + " -o " + dir, dir, "is a folder, not a file"},
      {"fit " + walk + " -o " + file + "/fitted.json", file + "/fitted.json",
       file + " is a file, not a folder"},
      {"clip from-motion " + walk + " -o " + file + "/a/b.json",
       file + "/a/b.json", file + " is a file, not a folder"},
      {"render " + walk + " -o " + dir, dir, "is a folder, not a file"},
      {"clip strip " + walk + " -o " + dir, dir, "is a folder, not a file"},
  };
  for (const Refused& r : refused) {
    SCOPED_TRACE(r.arguments);
    CommandResult result = RunMimic2d(r.arguments);
    EXPECT_EQ(result.exit_code, 105) << result.output;
    EXPECT_NE(result.output.find("--output"), std::string::npos)
        << result.output;
    EXPECT_NE(result.output.find("cannot write " + r.path + ": " + r.problem),
              std::string::npos)
        << result.output;
  }
  // Folders that do not exist yet are made on write.
  const std::string absolute = dir + "/new/deeper/walk.json";
  CommandResult result = RunMimic2d("clip from-motion " + walk +
                                    " --views 1 --duration 1 -o " + absolute);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(absolute));
  result = testing::RunCommand("cd " + dir + " && " + MIMIC2D_BINARY +
                               " clip from-motion " + walk +
                               " --views 1 --duration 1 -o zz/y.json");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir + "/zz/y.json"));
}

// Found by fuzzing: a document nested 50,000 deep crashed the reader
// (stack overflow); a folder or /dev/null read as an empty file.
TEST(Cli, DeepOrNonFileInputsAreNamedErrors) {
  const std::string dir = testing::TempDir("cli_deep");
  const std::string deep = WriteFile(
      dir, "deep.json",
      "{\"format\": \"mimic2d.clip\", \"bbox\": " + std::string(50000, '[') +
          std::string(50000, ']') + "}");
  ExpectInputError("clip info " + deep, deep, "nested more than 64 levels");
  ExpectInputError("clip info " + dir, dir, "is a folder, not a file");
  ExpectInputError("clip info /dev/null", "/dev/null", "not a regular file");
}

// `fit --truth`: a stripped walk fitted from its 2D, each view measured
// afterwards against the original's truth (and the objective explained
// term by term there and at the fit); a truth of another shape is named.
TEST(Cli, FitMeasuresEachViewAgainstAGivenTruth) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  const std::string dir = testing::TempDir("cli_fit_truth");
  const std::string truth = dir + "/walk.json",
                    stripped = dir + "/walk_2d.json";
  ASSERT_EQ(RunMimic2d("clip from-motion " + walk + " --views 2 -o " + truth)
                .exit_code,
            0);
  ASSERT_EQ(RunMimic2d("clip strip " + truth + " -o " + stripped).exit_code, 0);
  CommandResult result =
      RunMimic2d("fit " + stripped + " --focal 1000 --quiet --truth " + truth +
                 " -o " + dir + "/fitted.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  size_t at = 0;
  int measured = 0;
  while ((at = result.output.find("\n  against the truth: focal 0.0%", at)) !=
         std::string::npos) {
    ++measured;
    ++at;
  }
  EXPECT_EQ(measured, 2) << result.output;
  // With the objective term by term at the truth and at the fit.
  for (const char* line : {"\n  stage 3's terms at the truth: reprojection ",
                           "\n  stage 3's terms at the fit:   reprojection "}) {
    EXPECT_NE(result.output.find(line), std::string::npos) << result.output;
  }
  // The walk's fit lands within the accuracy table's figures for it.
  const size_t mean = result.output.find("mean over the views");
  ASSERT_NE(mean, std::string::npos) << result.output;
  const size_t pa = result.output.find("PA-MPJPE ", mean);
  ASSERT_NE(pa, std::string::npos);
  EXPECT_LT(std::stod(result.output.substr(pa + 9)), 60.0) << result.output;

  // `clip info --truth` measures the written fit again, without fitting:
  // the same figures as the fit printed.
  const CommandResult info =
      RunMimic2d("clip info " + dir + "/fitted.json --truth " + truth);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const size_t info_mean = info.output.find("mean over the views");
  ASSERT_NE(info_mean, std::string::npos) << info.output;
  const auto pitch_and_pa = [](const std::string& text, size_t from) {
    const size_t pitch = text.find(", pitch ", from);
    const size_t mpjpe = text.find(", MPJPE ", from);
    return text.substr(pitch, mpjpe - pitch) +
           text.substr(text.find("PA-MPJPE ", from), 14);
  };
  EXPECT_EQ(pitch_and_pa(info.output, info_mean),
            pitch_and_pa(result.output, mean))
      << info.output << result.output;
  ExpectInputError("clip info " + stripped + " --truth " + truth, stripped,
                   "no estimate to measure");

  ASSERT_EQ(RunMimic2d("clip from-motion " + walk + " --views 1 -o " + dir +
                       "/one_view.json")
                .exit_code,
            0);
  ExpectInputError("fit " + stripped + " --quiet --truth " + dir +
                       "/one_view.json -o " + dir + "/never.json",
                   dir + "/one_view.json", "--truth: 1 views");
  ExpectInputError("fit " + stripped + " --quiet --truth " + stripped + " -o " +
                       dir + "/never.json",
                   stripped, "holds no 3D truth");
  ExpectInputError(
      "clip info " + dir + "/fitted.json --truth " + dir + "/one_view.json",
      dir + "/one_view.json", "--truth: 1 views");
  // A rig is two or more views of one take.
  ExpectInputError(
      "fit " + dir + "/one_view.json --rig --quiet -o " + dir + "/never.json",
      dir + "/one_view.json", "needs 2 or more views");
  std::filesystem::remove_all(dir);
}

TEST(Cli, UnknownOrMissingCommandsListTheCommands) {
  CommandResult result = RunMimic2d("frobnicate");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("unknown command 'frobnicate'"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("clip, demo"), std::string::npos)
      << result.output;
  result = RunMimic2d("");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("no command given"), std::string::npos)
      << result.output;
  // A command's own help, not the main one.
  result = RunMimic2d("fit --help");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("mimic2d fit [OPTIONS] [input]"),
            std::string::npos)
      << result.output;
  // The input is optional only for --list-settings.
  result = RunMimic2d("fit");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("give an input bundle"), std::string::npos)
      << result.output;
  result = RunMimic2d("train --list-settings");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("`asi.anchor_share`"), std::string::npos)
      << result.output;
}

// `mimic2d keypoints` on a real recording (Debian opencv-doc's vtest.avi,
// pedestrians about 70 px tall): a clip of the frames read, at the video's
// rate and size, with a person in nearly every frame, and an overlay video.
TEST(Cli, KeypointsFollowAPersonInARealVideo) {
  const std::string dir = testing::TempDir("cli_keypoints");
  const std::string clip_path = dir + "/vtest.json";
  CommandResult result = RunMimic2d(
      "keypoints /usr/share/doc/opencv-doc/examples/data/vtest.avi "
      "--max-frames 40 --quiet -o " +
      clip_path + " --overlay " + dir + "/overlay.mp4");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  Clip2D clip = ReadClip(clip_path);
  EXPECT_EQ(clip.num_frames(), 40);
  EXPECT_DOUBLE_EQ(clip.fps, 10.0);
  EXPECT_EQ(clip.image_width_px, 768);
  EXPECT_EQ(clip.image_height_px, 576);
  int with_person = 0;
  for (int t = 0; t < clip.num_frames(); ++t) {
    int confident = 0;
    for (int j = 0; j < 17; ++j)
      confident += clip.keypoints.at(t, j).confidence > 0.3 ? 1 : 0;
    with_person += confident >= 8 ? 1 : 0;
  }
  EXPECT_GE(with_person, 36) << result.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/overlay.mp4"));
}

TEST(Cli, KeypointsNameBadVideosAndMissingModels) {
  const std::string dir = testing::TempDir("cli_keypoints_bad");
  const std::string text = WriteFile(dir, "notes.mp4", "not a video\n");
  CommandResult result =
      RunMimic2d("keypoints " + text + " -o " + dir + "/a.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find(text), std::string::npos) << result.output;

  result =
      RunMimic2d("keypoints " + dir + "/missing.mp4 -o " + dir + "/a.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("missing.mp4"), std::string::npos);

  result = RunMimic2d(
      "keypoints /usr/share/doc/opencv-doc/examples/data/vtest.avi --models " +
      dir + " -o " + dir + "/a.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find(dir + "/movenet-lightning.json"),
            std::string::npos)
      << result.output;

  // A grey video of 10 frames: nobody in it.
  const std::string grey = dir + "/grey.mp4";
  ASSERT_EQ(std::system(("ffmpeg -loglevel error -y -f lavfi -i "
                         "color=c=gray:s=320x240:r=10:d=1 " +
                         grey)
                            .c_str()),
            0);
  result = RunMimic2d("keypoints " + grey + " --quiet -o " + dir + "/a.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("no person found"), std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/a.json"));
}

}  // namespace
}  // namespace m2d
