#include "gen/generator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "common/error.h"
#include "eval/metrics.h"
#include "gen/feature_encoder.h"
#include "gen/gen_checkpoint.h"
#include "gen/gen_trainer.h"
#include "gen/motion_stream.h"

namespace m2d {

GenConfig ReadGeneratorConfig(const std::string& run_dir) {
  return LoadTokenizer(
             (std::filesystem::path(run_dir) / kTokenizerFile).string())
      .config;
}

GenConfig ReadPriorConfig(const std::string& run_dir) {
  return LoadPrior((std::filesystem::path(run_dir) / kPriorFile).string())
      .config;
}

namespace {

// `seconds` of motion streamed from loaded models.
GeneratedMotion Generate(const LoadedTokenizer& tokenizer,
                         const LoadedPrior& prior, double seconds,
                         const GenerationOptions& options) {
  GeneratedMotion motion;
  motion.fps = tokenizer.config.data.fps;
  MotionStream stream(tokenizer, prior, options);
  const int frame_size = stream.frame_size();
  motion.num_frames = static_cast<int>(std::ceil(seconds * motion.fps));
  const auto start = std::chrono::steady_clock::now();
  while (static_cast<int>(motion.rows.size()) < motion.num_frames * frame_size)
    stream.Next(&motion.rows);
  motion.generation_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  motion.rows.resize(static_cast<size_t>(motion.num_frames) * frame_size);
  motion.num_codes = static_cast<int>(stream.codes().size());
  return motion;
}

void CheckGeneration(double seconds, const SamplingOptions& sampling) {
  sampling.Validate();
  if (!(seconds > 0 && seconds <= 24 * 3600))
    throw ConfigError("generation length must be in (0, 86400] s");
}

}  // namespace

GeneratedMotion GenerateMotion(const std::string& run_dir, double seconds,
                               const GenerationOptions& generation) {
  CheckGeneration(seconds, generation.sampling);
  const std::filesystem::path run(run_dir);
  return Generate(LoadTokenizer((run / kTokenizerFile).string()),
                  LoadPrior((run / kPriorFile).string()), seconds, generation);
}

int GenerationView(const GenConfig& config, double azimuth_deg,
                   double elevation_deg, int motion) {
  if (motion < 0 || motion >= config.prior_motions())
    throw ConfigError("generate: --motion " + std::to_string(motion) +
                      " is not one of the prior's " +
                      std::to_string(config.prior_motions()) +
                      " motion(s) (data.motions, from 0)");
  if (config.prior_views() == 0) return -1;
  return config.PriorCondition(
      config.data.views.NearestView(azimuth_deg, elevation_deg), motion);
}

std::string GeneratorEvalResult::BriefReport() const {
  std::ostringstream out;
  out.precision(4);
  auto ratio = [&](double floor) { return floor > 0 ? fid / floor : 0.0; };
  out << "FID generated vs real " << fid << "; floors, real vs real: halves "
      << "in time " << fid_floor_time << " (ratio " << ratio(fid_floor_time)
      << "), halves by view " << fid_floor_views << " (ratio "
      << ratio(fid_floor_views) << "); as many real stretches as generations "
      << fid_floor_sampled << " (ratio " << ratio(fid_floor_sampled) << ")\n"
      << "FID of the tokenizer's reconstructions vs real " << fid_reconstruction
      << "; mean |error|: local pose " << reconstruction_pose_error
      << ", root step " << reconstruction_root_error << ", log-scale step "
      << reconstruction_scale_error << " (units of the body's scale)\n"
      << "FID of the real codes decoded as a stream vs real "
      << fid_stream_reconstruction << "\n"
      << "diversity real " << diversity_real << ", generated "
      << diversity_generated << "\n"
      << "precision " << precision << ", recall " << recall
      << " (real halves in time: " << precision_floor_time << ", "
      << recall_floor_time << "); recall by motion:";
  for (const auto& [motion, motion_recall] : recall_by_motion)
    out << " " << motion << " " << motion_recall;
  out << "\n"
      << "windows: real " << real_windows << ", held apart "
      << held_apart_windows << " (encoder loss " << encoder_loss
      << "), generated " << generated_windows << "\n"
      << "FID by time segment of the generations:";
  for (double segment_fid : fid_by_time_segment) out << " " << segment_fid;
  if (!fid_by_time_segment.empty())
    out << " (real stretches of a segment's length: "
        << fid_floor_sampled_segment << ")";
  out << "\n"
      << "placement drift over a generation (RMS): log scale generated "
      << drift_log_scale_generated << ", real " << drift_log_scale_real
      << "; root generated " << drift_root_generated << ", real "
      << drift_root_real << " body scales\n"
      << "jumps (a frame's largest keypoint step past the real data's 99.9th "
      << "percentile, " << jump_threshold << " body scales) per minute: "
      << "generated " << jumps_per_min_generated << " ("
      << 100.0 * jump_share_at_seams << " % at decoding seams), real codes "
      << "decoded as a stream " << jumps_per_min_stream << ", real "
      << jumps_per_min_real << "\n"
      << "generation speed " << realtime_factor
      << "x real time (1 thread, tokens + decoding)\n";
  return out.str();
}

GeneratorEvalResult EvaluateGenerator(const std::string& run_dir,
                                      const GenDataset& real,
                                      const GenDataset& held_apart,
                                      const GeneratorEvalOptions& options) {
  // Refused before any work: segments too short to hold a window.
  const int segment_frames = static_cast<int>(
      options.seconds * real.fps / std::max(1, options.time_segments));
  if (options.floor_draws < 1)
    throw ConfigError("gen eval: floor_draws must be at least 1");
  if (options.neighbours < 1)
    throw ConfigError("gen eval: neighbours (k) must be at least 1");
  if (options.time_segments < 1 || segment_frames < options.window_frames) {
    throw ConfigError(
        "gen eval: " + std::to_string(options.time_segments) +
        " time segments of " + std::to_string(options.seconds) +
        " s are shorter than a " + std::to_string(options.window_frames) +
        "-frame window; use fewer segments or longer generations");
  }
  const std::filesystem::path run(run_dir);
  LoadedTokenizer tokenizer = LoadTokenizer((run / kTokenizerFile).string());
  const int frame_size = real.frame_size;
  auto windows_of = [&](const std::vector<GenSequence>& sequences) {
    return DatasetWindows(sequences, frame_size, options.window_frames,
                          options.stride_frames, tokenizer.mean, tokenizer.std);
  };
  GeneratorEvalResult result;

  // 1. The encoder, trained on motion the generator never saw.
  const torch::Tensor held_windows = windows_of(held_apart.sequences);
  result.held_apart_windows = static_cast<int>(held_windows.size(0));
  FeatureEncoderOptions encoder_options;
  encoder_options.window_frames = options.window_frames;
  encoder_options.steps = options.encoder_steps;
  FeatureEncoder encoder =
      TrainFeatureEncoder(held_windows, frame_size, encoder_options,
                          options.seed, &result.encoder_loss);

  // 2. Real features, and the floors: the real sequences in two halves by
  // view, and in two halves in time.
  const torch::Tensor real_windows = windows_of(real.sequences);
  result.real_windows = static_cast<int>(real_windows.size(0));
  const Eigen::MatrixXd real_features = EncodeWindows(encoder, real_windows);
  auto features_of = [&](const std::vector<GenSequence>& sequences) {
    return EncodeWindows(encoder, windows_of(sequences));
  };
  {
    std::vector<GenSequence> by_view[2], by_time[2];
    for (size_t i = 0; i < real.sequences.size(); ++i)
      by_view[i % 2].push_back(real.sequences[i]);
    for (const GenSequence& sequence : real.sequences) {
      const auto [first, second] = SplitSequenceInTime(sequence, frame_size);
      by_time[0].push_back(first);
      by_time[1].push_back(second);
    }
    result.fid_floor_views =
        FrechetDistance(FitFeatureGaussian(features_of(by_view[0])),
                        FitFeatureGaussian(features_of(by_view[1])));
    const Eigen::MatrixXd first_half = features_of(by_time[0]),
                          second_half = features_of(by_time[1]);
    result.fid_floor_time = FrechetDistance(FitFeatureGaussian(first_half),
                                            FitFeatureGaussian(second_half));
    const PrecisionRecall halves =
        ManifoldPrecisionRecall(first_half, second_half, options.neighbours);
    result.precision_floor_time = halves.precision;
    result.recall_floor_time = halves.recall;
  }

  // The tokenizer alone: every real window encoded and decoded (windows
  // of the length it was trained on; decoding whole sequences at once was
  // 3x worse on the local pose: the network leans on the windows' edges).
  {
    torch::NoGradGuard no_grad;
    const torch::Tensor decoded =
        tokenizer.model->Decode(tokenizer.model->Encode(real_windows));
    const torch::Tensor error = (decoded - real_windows).abs() * tokenizer.std;
    const int pose = RootStepColumn(frame_size);  // the local pose before it
    result.reconstruction_pose_error =
        error.narrow(2, 0, pose).mean().item<double>();
    result.reconstruction_root_error =
        error.narrow(2, pose, 2).mean().item<double>();
    result.reconstruction_scale_error =
        error.narrow(2, pose + 2, 1).mean().item<double>();
    result.fid_reconstruction =
        FrechetDistance(FitFeatureGaussian(EncodeWindows(encoder, decoded)),
                        FitFeatureGaussian(real_features));
  }

  // Jumps: the real data's 99.9th percentile of the largest keypoint step
  // per frame is the threshold; how often a set of sequences passes it.
  {
    std::vector<double> real_steps;
    for (const GenSequence& sequence : real.sequences) {
      const std::vector<double> steps = LargestPoseSteps(sequence, frame_size);
      real_steps.insert(real_steps.end(), steps.begin(), steps.end());
    }
    if (!real_steps.empty()) {
      const size_t at = static_cast<size_t>(0.999 * (real_steps.size() - 1));
      std::nth_element(real_steps.begin(), real_steps.begin() + at,
                       real_steps.end());
      result.jump_threshold = real_steps[at];
    }
  }
  // Jumps per minute of `sequences`, and their share on a frame that
  // starts a decoding (every `seam_frames`; 0: not counted).
  struct Jumps {
    double per_min = 0.0, share_at_seams = 0.0;
  };
  auto count_jumps = [&](const std::vector<GenSequence>& sequences,
                         int seam_frames) {
    double jumps = 0.0, at_seams = 0.0, frames = 0.0;
    for (const GenSequence& sequence : sequences) {
      const std::vector<double> steps = LargestPoseSteps(sequence, frame_size);
      for (size_t i = 0; i < steps.size(); ++i) {
        if (steps[i] <= result.jump_threshold) continue;
        ++jumps;
        // Step i ends at frame i + 1.
        at_seams += seam_frames > 0 && (i + 1) % seam_frames == 0;
      }
      frames += sequence.num_frames;
    }
    Jumps counted;
    if (frames > 0) counted.per_min = jumps / (frames / real.fps / 60.0);
    if (jumps > 0) counted.share_at_seams = at_seams / jumps;
    return counted;
  };
  result.jumps_per_min_real = count_jumps(real.sequences, 0).per_min;

  // The streaming decoder alone: the codes the prior learns (every real
  // sequence encoded whole) decoded as a generation's are.
  {
    std::vector<int> kept;
    const std::vector<std::vector<int64_t>> code_sequences = TokenizeDataset(
        tokenizer.model, real, tokenizer.mean, tokenizer.std, &kept);
    std::vector<GenSequence> streamed;
    for (size_t i = 0; i < code_sequences.size(); ++i) {
      MotionStream stream(tokenizer, code_sequences[i], options.generation);
      const int64_t frames = stream.frames_available();
      std::vector<float> rows;
      while (static_cast<int64_t>(rows.size()) < frames * frame_size)
        stream.Next(&rows);
      streamed.push_back({"streamed/" + std::to_string(i),
                          static_cast<int>(frames), std::move(rows)});
    }
    result.jumps_per_min_stream = count_jumps(streamed, 0).per_min;
    result.fid_stream_reconstruction = FrechetDistance(
        FitFeatureGaussian(EncodeWindows(encoder, windows_of(streamed))),
        FitFeatureGaussian(real_features));
  }

  // The floors at the generations' sample size: as many real stretches as
  // generations, as long as a generation (and as a segment), scored alike.
  const FeatureGaussian real_gaussian = FitFeatureGaussian(real_features);
  auto sampled_floor = [&](int stretch_frames) {
    double sum = 0.0;
    for (int d = 0; d < options.floor_draws; ++d) {
      // Among the sequences that hold a window, as the real windows are (a
      // once-played kick of 46 frames holds none).
      const std::vector<GenSequence> stretches = DrawRealStretches(
          real.sequences, frame_size, stretch_frames, options.generations,
          options.window_frames, options.seed + 1000 + d);
      sum += FrechetDistance(
          FitFeatureGaussian(EncodeWindows(encoder, windows_of(stretches))),
          real_gaussian);
    }
    return sum / options.floor_draws;
  };
  const int generation_frames =
      static_cast<int>(std::lround(options.seconds * real.fps));
  result.fid_floor_sampled = sampled_floor(generation_frames);
  if (options.time_segments > 1) {
    result.fid_floor_sampled_segment = sampled_floor(segment_frames);
  }

  // 3. Generated features; generation timed on one thread.
  const int threads = torch::get_num_threads();
  torch::set_num_threads(1);
  std::vector<GenSequence> generated;
  double generation_s = 0.0, generated_s = 0.0;
  CheckGeneration(options.seconds, options.generation.sampling);
  const LoadedPrior prior = LoadPrior((run / kPriorFile).string());
  const int views = prior.config.prior_views();
  // A prior conditioned on the motion generates the motions in proportion
  // to their frames in the data, stratified: generation g takes the motion
  // whose share of the frames holds (g + 1/2) / generations.
  std::vector<double> motion_frames(prior.config.prior_motions(), 0.0);
  for (const GenSequence& sequence : real.sequences) {
    if (prior.config.prior.condition_on_motion &&
        sequence.motion < static_cast<int>(motion_frames.size()))
      motion_frames[sequence.motion] += sequence.num_frames;
  }
  double total_frames = 0.0;
  for (double frames : motion_frames) total_frames += frames;
  auto motion_of = [&](int g) {
    double cumulative = 0.0;
    const double at = (g + 0.5) / options.generations * total_frames;
    for (size_t m = 0; m < motion_frames.size(); ++m) {
      cumulative += motion_frames[m];
      if (at < cumulative) return static_cast<int>(m);
    }
    return 0;
  };
  for (int g = 0; g < options.generations; ++g) {
    GenerationOptions generation = options.generation;
    generation.seed = static_cast<uint64_t>(g + 1);
    generation.view =
        views > 0 ? prior.config.PriorCondition(g % views, motion_of(g)) : -1;
    GeneratedMotion motion =
        Generate(tokenizer, prior, options.seconds, generation);
    generation_s += motion.generation_s;
    generated_s += motion.num_frames / motion.fps;
    generated.push_back({"generated/" + std::to_string(g + 1),
                         motion.num_frames, std::move(motion.rows)});
  }
  torch::set_num_threads(threads);
  result.realtime_factor = generated_s / std::max(1e-9, generation_s);
  const torch::Tensor generated_windows = windows_of(generated);
  result.generated_windows = static_cast<int>(generated_windows.size(0));
  const Eigen::MatrixXd generated_features =
      EncodeWindows(encoder, generated_windows);

  // 4. The figures.
  auto rms_drift = [&](const std::vector<GenSequence>& sequences,
                       double* log_scale, double* root) {
    double scale_sum = 0.0, root_sum = 0.0;
    for (const GenSequence& sequence : sequences) {
      const PlacementDrift drift = PlacementDriftOf(sequence, frame_size);
      scale_sum += drift.log_scale_change * drift.log_scale_change;
      root_sum += drift.root_displacement.squaredNorm();
    }
    const double count = std::max<size_t>(1, sequences.size());
    *log_scale = std::sqrt(scale_sum / count);
    *root = std::sqrt(root_sum / count);
  };
  {
    const Jumps generated_jumps =
        count_jumps(generated, options.generation.decoding.emit_codes *
                                   tokenizer.model->frames_per_token());
    result.jumps_per_min_generated = generated_jumps.per_min;
    result.jump_share_at_seams = generated_jumps.share_at_seams;
  }
  rms_drift(generated, &result.drift_log_scale_generated,
            &result.drift_root_generated);
  rms_drift(DrawRealStretches(real.sequences, frame_size, generation_frames,
                              options.generations, options.window_frames,
                              options.seed + 1000),
            &result.drift_log_scale_real, &result.drift_root_real);
  result.fid =
      FrechetDistance(FitFeatureGaussian(generated_features), real_gaussian);
  const PrecisionRecall coverage = ManifoldPrecisionRecall(
      real_features, generated_features, options.neighbours);
  result.precision = coverage.precision;
  result.recall = coverage.recall;
  {
    // Each motion's windows alone on the generated manifold: which motions
    // the generations leave out.
    const Eigen::VectorXd generated_radii =
        KthNeighbourDistances(generated_features, options.neighbours);
    std::map<std::string, std::vector<GenSequence>> by_motion;
    for (const GenSequence& sequence : real.sequences)
      by_motion[sequence.name.substr(0, sequence.name.find('/'))].push_back(
          sequence);
    for (const auto& [motion, sequences] : by_motion) {
      bool has_window = false;
      for (const GenSequence& sequence : sequences)
        has_window |= sequence.num_frames >= options.window_frames;
      if (!has_window) continue;
      result.recall_by_motion.push_back(
          {motion, ShareWithinRadii(features_of(sequences), generated_features,
                                    generated_radii)});
    }
  }
  result.diversity_real = MeanPairDistance(real_features, 300, options.seed);
  result.diversity_generated =
      MeanPairDistance(generated_features, 300, options.seed);
  if (options.time_segments > 1) {
    std::vector<std::vector<GenSequence>> segments(options.time_segments);
    for (const GenSequence& sequence : generated) {
      std::vector<GenSequence> parts =
          CutSequenceInTime(sequence, frame_size, options.time_segments);
      for (int k = 0; k < options.time_segments; ++k)
        segments[k].push_back(std::move(parts[k]));
    }
    for (const std::vector<GenSequence>& segment : segments) {
      result.fid_by_time_segment.push_back(FrechetDistance(
          FitFeatureGaussian(EncodeWindows(encoder, windows_of(segment))),
          real_gaussian));
    }
  }
  return result;
}

}  // namespace m2d
