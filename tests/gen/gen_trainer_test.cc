#include "gen/gen_trainer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "common/error.h"
#include "common/file_io.h"
#include "gen/gen_checkpoint.h"
#include "gen/gen_test_data.h"
#include "gen/generated_stream.h"
#include "gen/generator.h"
#include "gen/motion_stream.h"
#include "motion/canonical.h"

namespace m2d {
namespace {

GenDataset WalkDataset() { return testing::ClipDataset("walk", 2, {10}, 4.0); }

GenConfig TinyConfig(const std::string& run_dir) {
  GenConfig config;
  config.tokenizer.num_codes = 16;
  config.tokenizer.code_size = 16;
  config.tokenizer.width = 32;
  config.tokenizer.residual_depth = 1;
  config.tokenizer.window_frames = 16;
  config.tokenizer.batch_size = 4;
  config.tokenizer.steps = 6;
  config.prior.num_layers = 1;
  config.prior.num_heads = 2;
  config.prior.embedding = 16;
  config.prior.context_tokens = 8;
  config.prior.batch_size = 4;
  config.prior.steps = 4;
  config.run.run_dir = run_dir;
  config.run.torch_threads = 1;
  config.Validate();
  return config;
}

// The FID protocol at a tiny size: 16-frame windows, a few encoder steps.
GeneratorEvalOptions TinyEvalOptions(double seconds, int time_segments) {
  GeneratorEvalOptions options;
  options.generations = 2;
  options.seconds = seconds;
  options.window_frames = 16;
  options.stride_frames = 8;
  options.encoder_steps = 20;
  options.encoders = 2;
  options.time_segments = time_segments;
  return options;
}

std::string TempRun(const std::string& name) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("m2d_gen_" + name)).string();
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(GenTrainer, AResumedRunEndsWhereAnUninterruptedOneDoes) {
  const GenDataset dataset = WalkDataset();
  // Straight through.
  const GenConfig straight = TinyConfig(TempRun("straight"));
  TrainGenerator(straight, dataset, false, nullptr, nullptr);
  // Stopped after the first tokenizer step, then resumed.
  const GenConfig stopped = TinyConfig(TempRun("resumed"));
  std::atomic<bool> stop{false};
  GenTrainSummary first = TrainGenerator(
      stopped, dataset, false, &stop, [&](const GenProgress&) { stop = true; });
  EXPECT_TRUE(first.interrupted);
  EXPECT_EQ(first.tokenizer_steps, 1);
  GenTrainSummary second =
      TrainGenerator(stopped, dataset, true, nullptr, nullptr);
  EXPECT_FALSE(second.interrupted);
  EXPECT_EQ(second.tokenizer_steps, 6);
  EXPECT_EQ(second.prior_steps, 4);

  LoadedTokenizer a = LoadTokenizer(straight.run.run_dir + "/tokenizer.pt");
  LoadedTokenizer b = LoadTokenizer(stopped.run.run_dir + "/tokenizer.pt");
  auto pa = a.model->named_parameters(), pb = b.model->named_parameters();
  for (const auto& item : pa)
    EXPECT_TRUE(torch::equal(item.value(), pb[item.key()])) << item.key();
  auto ba = a.model->named_buffers(), bb = b.model->named_buffers();
  for (const auto& item : ba)
    EXPECT_TRUE(torch::equal(item.value(), bb[item.key()])) << item.key();
  // The log: one row per reported step, none twice.
  const std::string log =
      ReadFileText(stopped.run.run_dir + "/tokenizer_log.csv");
  EXPECT_EQ(log.find("\n1,"), log.rfind("\n1,"));
  EXPECT_NE(log.find("\n6,"), std::string::npos);
}

// run.adapt_torch_threads: the steps run with torch_threads or 1 thread as
// a SpeedTuner measures them, every report says which, and the stages
// finish as without it; the setting needs torch_threads >= 2.
TEST(GenTrainer, AdaptiveThreadsReportWhatTheStepsRunWith) {
  GenConfig config = TinyConfig(TempRun("adaptive_threads"));
  config.run.torch_threads = 2;
  config.run.adapt_torch_threads = true;
  config.tokenizer.steps = 12;  // past the tuner's first probe (4 steps)
  config.Validate();
  std::vector<int> reported;
  const GenTrainSummary summary = TrainGenerator(
      config, WalkDataset(), false, nullptr,
      [&](const GenProgress& p) { reported.push_back(p.torch_threads); });
  EXPECT_FALSE(summary.interrupted);
  EXPECT_EQ(summary.tokenizer_steps, 12);
  EXPECT_EQ(summary.prior_steps, 4);
  ASSERT_FALSE(reported.empty());
  for (int threads : reported) EXPECT_TRUE(threads == 1 || threads == 2);
  // Without the setting the configured count is reported.
  reported.clear();
  config.run.adapt_torch_threads = false;
  config.run.run_dir = TempRun("fixed_threads");
  TrainGenerator(
      config, WalkDataset(), false, nullptr,
      [&](const GenProgress& p) { reported.push_back(p.torch_threads); });
  for (int threads : reported) EXPECT_EQ(threads, 2);
  config.run.torch_threads = 1;
  config.run.adapt_torch_threads = true;
  EXPECT_THROW(config.Validate(), ConfigError);
}

// The prior's held-out tail (the last context of codes of every long
// sequence): its cross-entropy is logged at every report.
TEST(GenTrainer, ThePriorLogsItsHeldOutCrossEntropy) {
  const GenDataset dataset = WalkDataset();  // 30 codes per sequence
  const GenConfig config = TinyConfig(TempRun("held_out"));
  TrainGenerator(config, dataset, false, nullptr, nullptr);
  std::istringstream log(ReadFileText(config.run.run_dir + "/prior_log.csv"));
  std::string line;
  std::getline(log, line);
  EXPECT_NE(line.find(",validation_cross_entropy"), std::string::npos);
  int rows = 0;
  while (std::getline(log, line)) {
    const double held_out = std::stod(line.substr(line.rfind(',') + 1));
    EXPECT_TRUE(std::isfinite(held_out)) << line;
    EXPECT_GT(held_out, 0.0) << line;
    ++rows;
  }
  EXPECT_GE(rows, 2);
}

TEST(GenTrainer, TheTrainedGeneratorStreamsFrames) {
  const GenDataset dataset = WalkDataset();
  const GenConfig config = TinyConfig(TempRun("stream"));
  TrainGenerator(config, dataset, false, nullptr, nullptr);
  GenerationOptions options;
  options.seed = 3;
  MotionStream stream(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                      LoadPrior(config.run.run_dir + "/prior.pt"), options);
  std::vector<float> rows;
  for (int i = 0; i < 20; ++i) stream.Next(&rows);  // past the context
  EXPECT_EQ(rows.size(), 20u * 4 * 37);
  for (float value : rows) ASSERT_TRUE(std::isfinite(value));
  // Decoding 4 codes at a time (the default) draws up to 4 + the
  // lookahead codes ahead of the frames emitted.
  EXPECT_GE(stream.codes().size(), 21u);
  EXPECT_LE(stream.codes().size(), 25u);

  // A decoding per code emits the same number of frames from the same
  // codes (the sampler does not depend on how frames are decoded).
  options.decoding.emit_codes = 1;
  MotionStream per_code(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                        LoadPrior(config.run.run_dir + "/prior.pt"), options);
  std::vector<float> per_code_rows;
  for (int i = 0; i < 20; ++i) per_code.Next(&per_code_rows);
  EXPECT_EQ(per_code_rows.size(), rows.size());
  for (size_t i = 0; i < per_code.codes().size(); ++i)
    EXPECT_EQ(per_code.codes()[i], stream.codes()[i]);
  // An anchored placement changes the root and scale steps only, and
  // holds them nearer the start.
  options.decoding.emit_codes = 4;
  options.placement_return_s = 0.5;
  MotionStream anchored(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                        LoadPrior(config.run.run_dir + "/prior.pt"), options);
  std::vector<float> anchored_rows;
  for (int i = 0; i < 20; ++i) anchored.Next(&anchored_rows);
  ASSERT_EQ(anchored_rows.size(), rows.size());
  int changed = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (i % 37 < 34) {
      ASSERT_EQ(anchored_rows[i], rows[i]) << "local pose, row " << i / 37;
    } else {
      changed += anchored_rows[i] != rows[i];
    }
  }
  EXPECT_GT(changed, 0);
  // Settings it cannot keep.
  options.placement_return_s = 0.0;
  options.decoding.emit_codes = 16;
  EXPECT_THROW(
      MotionStream(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                   LoadPrior(config.run.run_dir + "/prior.pt"), options),
      ConfigError);
}

// Each decoding's first frames fade in from what the decoding before it
// made of them in its lookahead: the seam between two decoder passes does
// not jump (gen_config.h, StreamDecoding::blend_seams).
TEST(GenTrainer, ADecodingFadesInFromThePreviousOnesLookahead) {
  const GenConfig config = TinyConfig(TempRun("seams"));
  TrainGenerator(config, WalkDataset(), false, nullptr, nullptr);
  auto stream_rows = [&](int emit_codes, int lookahead_codes, bool blend) {
    GenerationOptions options;
    options.seed = 7;
    options.placement_return_s = 0.0;  // the rows as decoded
    options.decoding.emit_codes = emit_codes;
    options.decoding.lookahead_codes = lookahead_codes;
    options.decoding.blend_seams = blend;
    MotionStream stream(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                        LoadPrior(config.run.run_dir + "/prior.pt"), options);
    std::vector<float> rows;
    for (int i = 0; i < 8; ++i) stream.Next(&rows);
    return rows;
  };
  const size_t row = 37;
  const std::vector<float> blended = stream_rows(4, 1, true);
  const std::vector<float> seams = stream_rows(4, 1, false);
  // The first decoding's window, codes 0..4, decoded with code 4 emitted:
  // what the blended stream's first decoding saw in its lookahead.
  const std::vector<float> lookahead = stream_rows(5, 0, false);
  ASSERT_EQ(blended.size(), 8 * 4 * row);
  ASSERT_EQ(seams.size(), blended.size());
  int differing = 0;
  for (size_t i = 0; i < blended.size(); ++i) {
    const size_t frame = i / row;
    if (frame < 16 || frame >= 20) {
      // The first decoding has nothing before it; after the overlap the
      // second decoding's own frames.
      ASSERT_FLOAT_EQ(blended[i], seams[i]) << "frame " << frame;
    } else {
      // Code 4's frames: weights 1/5 .. 4/5 on the second decoding.
      const float weight = static_cast<float>(frame - 16 + 1) / 5.0f;
      EXPECT_NEAR(blended[i],
                  (1.0f - weight) * lookahead[i] + weight * seams[i], 1e-5)
          << "frame " << frame;
      differing += std::abs(lookahead[i] - seams[i]) > 1e-4f;
    }
  }
  EXPECT_GT(differing, 0);  // the two passes disagreed at the seam
  // Without a lookahead there is nothing to fade in from.
  EXPECT_EQ(stream_rows(4, 0, true), stream_rows(4, 0, false));
}

// Replayed, a stream's codes decode to the frames the drawing stream
// emitted (the eval's stream-reconstruction FID decodes real codes so), and
// the replay says how many frames its codes hold and stops there.
TEST(GenTrainer, ReplayedCodesDecodeAsTheDrawnOnes) {
  const GenConfig config = TinyConfig(TempRun("replay"));
  TrainGenerator(config, WalkDataset(), false, nullptr, nullptr);
  GenerationOptions options;
  options.seed = 5;
  options.placement_return_s = 2.0;
  MotionStream drawn(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                     LoadPrior(config.run.run_dir + "/prior.pt"), options);
  std::vector<float> rows;
  for (int i = 0; i < 12; ++i) drawn.Next(&rows);  // past the context
  EXPECT_EQ(drawn.frames_available(), 0);          // drawing: no limit
  // Decoding 4 codes at a time with 2 of lookahead: 12 emitted codes drew
  // 14 (the third decoding needed codes 8..13).
  ASSERT_EQ(drawn.codes().size(), 14u);
  MotionStream replayed(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                        drawn.codes(), options);
  EXPECT_EQ(replayed.frames_available(), 12 * 4);
  std::vector<float> replayed_rows;
  replayed.Next(&replayed_rows);
  EXPECT_EQ(replayed.frames_available(), 11 * 4);
  for (int i = 1; i < 12; ++i) replayed.Next(&replayed_rows);
  ASSERT_EQ(replayed_rows.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i)
    ASSERT_FLOAT_EQ(replayed_rows[i], rows[i]) << "row " << i / 37;
  EXPECT_EQ(replayed.frames_available(), 0);
  EXPECT_THROW(replayed.Next(&replayed_rows), ConfigError);
  // A code the tokenizer does not have is refused.
  EXPECT_THROW(MotionStream(LoadTokenizer(config.run.run_dir + "/tokenizer.pt"),
                            std::vector<int64_t>{0, 3, 16}, options),
               ConfigError);
}

// Streamed frame by frame, the generator gives the clip `generate` writes
// for the same seed and placement: the same codes, decoded alike, turned
// into absolute 2D by the same recurrence.
TEST(GenTrainer, TheGeneratedStreamIsTheGeneratedClip) {
  const GenConfig config = TinyConfig(TempRun("generated_stream"));
  TrainGenerator(config, WalkDataset(), false, nullptr, nullptr);
  const SamplingOptions sampling{0.9, 0};
  GenerationOptions generation;
  generation.sampling = sampling;
  generation.seed = 7;
  const GeneratedMotion motion =
      GenerateMotion(config.run.run_dir, 3.0, generation);
  const Eigen::Vector2d root_px(900, 600);
  const double scale_px = 80.0;
  const Clip2D clip = FromCanonical(
      CanonicalFromFeatures(motion.rows.data(), motion.num_frames,
                            Coco17Layout(), motion.fps, root_px, scale_px));
  GeneratedStreamOptions options;
  options.generation = generation;
  options.first_root_px = root_px;
  options.first_scale_px = scale_px;
  GeneratedStream stream(config.run.run_dir, options);
  EXPECT_EQ(stream.format().layout, &Coco17Layout());
  EXPECT_DOUBLE_EQ(stream.format().fps, motion.fps);
  std::vector<Keypoint2D> frame;
  double worst_px = 0.0;
  for (int t = 0; t < clip.num_frames(); ++t) {
    ASSERT_TRUE(stream.Next(&frame));
    ASSERT_EQ(frame.size(), 17u);
    for (int j = 0; j < 17; ++j) {
      worst_px = std::max(
          {worst_px, std::abs(frame[j].x_px - clip.keypoints.at(t, j).x_px),
           std::abs(frame[j].y_px - clip.keypoints.at(t, j).y_px)});
    }
  }
  EXPECT_LT(worst_px, 1e-6);
  options.generation.sampling.temperature = 0.0;
  EXPECT_THROW(GeneratedStream(config.run.run_dir, options), ConfigError);
}

TEST(GenTrainer, TheTrainedGeneratorIsMeasured) {
  // The FID protocol's plumbing on a tiny run: every count and figure is
  // there and finite (FeatureEncoder's test checks what FID separates).
  const GenDataset walk = WalkDataset();
  const GenConfig config = TinyConfig(TempRun("measured"));
  TrainGenerator(config, walk, false, nullptr, nullptr);
  // Segments of 45 frames: 4 windows per generation.
  GeneratorEvalOptions options = TinyEvalOptions(3.0, 2);
  const GeneratorEvalResult result =
      EvaluateGenerator(config.run.run_dir, walk, walk, options);
  EXPECT_EQ(result.generated_windows, 2 * ((90 - 16) / 8 + 1));
  // Two encoders: every feature figure is their mean, and the first one's
  // figures are what it scores alone.
  ASSERT_EQ(result.by_encoder.size(), 2u);
  EXPECT_NEAR(result.fid,
              0.5 * (result.by_encoder[0].fid + result.by_encoder[1].fid),
              1e-9 * (1.0 + result.fid));
  EXPECT_NEAR(result.fid_floor_time,
              0.5 * (result.by_encoder[0].fid_floor_time +
                     result.by_encoder[1].fid_floor_time),
              1e-9 * (1.0 + result.fid_floor_time));
  EXPECT_NE(result.by_encoder[0].fid, result.by_encoder[1].fid);
  {
    GeneratorEvalOptions alone = options;
    alone.encoders = 1;
    const GeneratorEvalResult single =
        EvaluateGenerator(config.run.run_dir, walk, walk, alone);
    ASSERT_EQ(single.by_encoder.size(), 1u);
    EXPECT_DOUBLE_EQ(single.fid, result.by_encoder[0].fid);
    EXPECT_DOUBLE_EQ(single.fid_floor_time,
                     result.by_encoder[0].fid_floor_time);
    ASSERT_EQ(single.recall_by_motion.size(), result.recall_by_motion.size());
    alone.encoders = 0;
    EXPECT_THROW(EvaluateGenerator(config.run.run_dir, walk, walk, alone),
                 ConfigError);
  }
  EXPECT_GT(result.real_windows, 0);
  EXPECT_GE(result.fid, 0.0);
  EXPECT_GE(result.fid_floor_views, 0.0);
  EXPECT_GE(result.fid_floor_time, 0.0);
  EXPECT_GE(result.fid_floor_sampled, 0.0);
  EXPECT_GE(result.fid_floor_sampled_segment, 0.0);
  EXPECT_TRUE(std::isfinite(result.fid_stream_reconstruction));
  EXPECT_GE(result.fid_stream_reconstruction, 0.0);
  EXPECT_TRUE(std::isfinite(result.fid_floor_sampled));
  // Real data with sequences shorter than a window (a clip played once):
  // the floors draw among those that hold one, as the real windows do.
  GenDataset with_short = walk;
  for (const GenSequence& sequence : walk.sequences) {
    const int short_frames = options.window_frames - 1;
    with_short.sequences.push_back(
        {sequence.name + "/short",
         short_frames,
         {sequence.features.begin(),
          sequence.features.begin() +
              static_cast<size_t>(short_frames) * walk.frame_size}});
  }
  const GeneratorEvalResult short_result =
      EvaluateGenerator(config.run.run_dir, with_short, walk, options);
  EXPECT_TRUE(std::isfinite(short_result.fid_floor_sampled));
  EXPECT_EQ(short_result.real_windows, result.real_windows);
  EXPECT_GT(result.diversity_generated, 0.0);
  for (double drift :
       {result.drift_log_scale_generated, result.drift_log_scale_real,
        result.drift_root_generated, result.drift_root_real}) {
    EXPECT_TRUE(std::isfinite(drift));
    EXPECT_GE(drift, 0.0);
  }
  EXPECT_GT(result.realtime_factor, 1.0);
  // Jumps: counted against a threshold the real data sets.
  EXPECT_GT(result.jump_threshold, 0.0);
  EXPECT_GE(result.jumps_per_min_generated, 0.0);
  EXPECT_GE(result.jumps_per_min_stream, 0.0);
  // The real motion passes its own 99.9th percentile on about 0.1 % of
  // its frames (fewer with ties at the threshold).
  EXPECT_GE(result.jumps_per_min_real, 0.0);
  EXPECT_LE(result.jumps_per_min_real, 0.01 * 30 * 60);
  EXPECT_GE(result.jump_share_at_seams, 0.0);
  EXPECT_LE(result.jump_share_at_seams, 1.0);
  EXPECT_TRUE(std::isfinite(result.fid));
  ASSERT_EQ(result.fid_by_time_segment.size(), 2u);
  for (double segment_fid : result.fid_by_time_segment) {
    EXPECT_TRUE(std::isfinite(segment_fid));
    EXPECT_GE(segment_fid, 0.0);
  }
  // Segments shorter than a window are refused, not scored on nothing.
  options.time_segments = 10;
  EXPECT_THROW(EvaluateGenerator(config.run.run_dir, walk, walk, options),
               ConfigError);
  // What a user gets from `generate`: the frames asked for, finite.
  GenerationOptions generation;
  generation.sampling = SamplingOptions{0.8, 5};
  generation.seed = 4;
  const GeneratedMotion motion =
      GenerateMotion(config.run.run_dir, 2.0, generation);
  EXPECT_EQ(motion.num_frames, 60);
  EXPECT_EQ(motion.rows.size(), 60u * 37);
  generation.sampling.temperature = 0.0;
  EXPECT_THROW(GenerateMotion(config.run.run_dir, 2.0, generation),
               ConfigError);
}

TEST(GenTrainer, AViewConditionedPriorGeneratesTheViewAskedFor) {
  // The walk from 2 azimuths (30 and 210 deg) at 10 deg: a prior
  // conditioned on the view has a token for each, generation asks for
  // one, and a view it does not have is refused.
  GenConfig config = TinyConfig(TempRun("view"));
  config.prior.condition_on_view = true;
  // A dataset seen from views the config does not name is refused.
  EXPECT_THROW(TrainGenerator(config, WalkDataset(), false, nullptr, nullptr),
               ConfigError);
  config.data.views.num_azimuths = 2;  // WalkDataset's views
  config.data.views.elevations_deg = {10};
  TrainGenerator(config, WalkDataset(), false, nullptr, nullptr);
  const LoadedPrior prior = LoadPrior(config.run.run_dir + "/prior.pt");
  EXPECT_EQ(prior.model->num_views(), 2);
  EXPECT_EQ(ReadPriorConfig(config.run.run_dir).prior_views(), 2);
  EXPECT_EQ(GenerationView(config, 200, 0), 1);
  EXPECT_EQ(GenerationView(config, 30, 40), 0);
  EXPECT_EQ(GenerationView(TinyConfig("unconditioned"), 200, 0), -1);
  GenerationOptions generation;
  generation.seed = 3;
  generation.view = 1;
  const GeneratedMotion motion =
      GenerateMotion(config.run.run_dir, 2.0, generation);
  EXPECT_EQ(motion.num_frames, 60);
  for (float value : motion.rows) ASSERT_TRUE(std::isfinite(value));
  for (int view : {-1, 2}) {
    generation.view = view;
    EXPECT_THROW(GenerateMotion(config.run.run_dir, 2.0, generation),
                 ConfigError);
  }
  GeneratedStreamOptions stream_options;
  stream_options.generation.view = 0;
  GeneratedStream stream(config.run.run_dir, stream_options);
  std::vector<Keypoint2D> frame;
  for (int t = 0; t < 40; ++t) ASSERT_TRUE(stream.Next(&frame));
  // The evaluation generates every view in turn.
  EXPECT_TRUE(
      std::isfinite(EvaluateGenerator(config.run.run_dir, WalkDataset(),
                                      WalkDataset(), TinyEvalOptions(2.0, 1))
                        .fid));
}

TEST(GenTrainer, AMotionConditionedPriorHasATokenPerViewAndMotion) {
  // The walk and the run from 2 azimuths at 10 deg: the condition token
  // names a view and a motion (view + views x motion), generation asks
  // for one of each, and the evaluation spreads its generations over the
  // motions.
  GenViewOptions views;
  views.num_azimuths = 2;
  views.elevations_deg = {10};
  const GenDataset dataset = BuildGenDataset(
      {testing::DeepMimicSource("walk"), testing::DeepMimicSource("run")},
      views, 30.0, 4.0);
  ASSERT_EQ(dataset.sequences.size(), 4u);
  EXPECT_EQ(dataset.sequences[1].motion, 0);
  EXPECT_EQ(dataset.sequences[2].motion, 1);
  EXPECT_EQ(dataset.sequences[2].view, 0);
  GenConfig config = TinyConfig(TempRun("motion"));
  config.data.views = views;
  config.data.motions = {"assets/motions/deepmimic/humanoid3d_walk.txt",
                         "assets/motions/deepmimic/humanoid3d_run.txt"};
  config.prior.condition_on_motion = true;
  EXPECT_THROW(config.Validate(), ConfigError);  // needs the view's token
  config.prior.condition_on_view = true;
  config.Validate();
  EXPECT_EQ(config.prior_conditions(), 4);
  EXPECT_EQ(config.PriorCondition(1, 1), 3);
  {  // A dataset of more motions than the config names is refused.
    GenConfig one_motion = config;
    one_motion.data.motions.resize(1);
    EXPECT_THROW(TrainGenerator(one_motion, dataset, false, nullptr, nullptr),
                 ConfigError);
  }
  TrainGenerator(config, dataset, false, nullptr, nullptr);
  const LoadedPrior prior = LoadPrior(config.run.run_dir + "/prior.pt");
  EXPECT_EQ(prior.model->num_views(), 4);
  EXPECT_EQ(GenerationView(config, 200, 0, 1), 3);
  EXPECT_EQ(GenerationView(config, 30, 0, 0), 0);
  EXPECT_THROW(GenerationView(config, 30, 0, 2), ConfigError);
  EXPECT_THROW(GenerationView(TinyConfig("unconditioned"), 30, 0, 1),
               ConfigError);
  GenerationOptions generation;
  generation.view = 3;
  const GeneratedMotion motion =
      GenerateMotion(config.run.run_dir, 2.0, generation);
  EXPECT_EQ(motion.num_frames, 60);
  EXPECT_TRUE(std::isfinite(EvaluateGenerator(config.run.run_dir, dataset,
                                              dataset, TinyEvalOptions(2.0, 1))
                                .fid));
}

TEST(GenTrainer, ADamagedCheckpointIsNamed) {
  const std::string dir = TempRun("damaged");
  std::filesystem::create_directories(dir);
  WriteFileAtomic(dir + "/tokenizer.pt", "not an archive");
  try {
    LoadTokenizer(dir + "/tokenizer.pt");
    FAIL() << "loaded a damaged checkpoint";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tokenizer.pt"), std::string::npos);
  }
  // A tracking checkpoint is not a tokenizer.
  const GenConfig config = TinyConfig(TempRun("other"));
  EXPECT_THROW(LoadPrior(dir + "/tokenizer.pt"), InputError);
}

TEST(GenConfig, ReadsBackWhatItWrites) {
  GenConfig config = TinyConfig("runs/x");
  const GenConfig back = LoadGenConfigText(GenConfigToYaml(config), "test");
  EXPECT_EQ(GenConfigToYaml(back), GenConfigToYaml(config));
  EXPECT_THROW(LoadGenConfigText("tokenizer: {num_codes: 1}\n", "bad.yaml"),
               InputError);
  EXPECT_THROW(
      LoadGenConfigText("tokenizer: {window_frames: 30}\n", "bad.yaml"),
      InputError);
  EXPECT_THROW(
      LoadGenConfigText("prior: {embedding: 30, num_heads: 4}\n", "bad.yaml"),
      InputError);
  EXPECT_THROW(LoadGenConfigText("prior: {unknown: 1}\n", "bad.yaml"),
               InputError);
}

TEST(GenConfig, EveryShippedConfigLoadsAndTheDocsListEverySetting) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(
           testing::SourcePath("configs/gen"))) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(LoadGenConfig(entry.path().string()));
    ++loaded;
  }
  EXPECT_GE(loaded, 1);
  // docs/generation.md carries the reference table (regenerate with
  // `mimic2d gen train --list-settings`).
  const std::string docs =
      ReadFileText(testing::SourcePath("docs/generation.md"));
  EXPECT_NE(docs.find(GenSettingsReference()), std::string::npos)
      << "docs/generation.md's settings table is stale";
}

}  // namespace
}  // namespace m2d
