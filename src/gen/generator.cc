#include "gen/generator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
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
      << "feature encoders " << by_encoder.size()
      << " (every feature figure is their mean); FID / halves-in-time "
      << "floor by encoder:";
  double ratio_sum = 0.0, ratio_square_sum = 0.0;
  for (const GeneratorFeatureFigures& figures : by_encoder) {
    const double encoder_ratio =
        figures.fid_floor_time > 0 ? figures.fid / figures.fid_floor_time : 0.0;
    out << " " << encoder_ratio;
    ratio_sum += encoder_ratio;
    ratio_square_sum += encoder_ratio * encoder_ratio;
  }
  if (by_encoder.size() > 1) {
    // The spread of one encoder's ratio, and the standard error of their
    // mean: how far another set of encoders (or another CPU's) may move it.
    const double count = static_cast<double>(by_encoder.size());
    const double mean = ratio_sum / count;
    const double deviation = std::sqrt(std::max(
        0.0, (ratio_square_sum - count * mean * mean) / (count - 1.0)));
    out << " (mean " << mean << ", standard deviation " << deviation
        << ", standard error of the mean " << deviation / std::sqrt(count)
        << ")";
  }
  out << "\n"
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

namespace {

// Calls f(a.x, b.x) for every scalar figure x of GeneratorFeatureFigures:
// the one list of them.
template <typename Figures, typename Other, typename F>
void ForEachScalarFigure(Figures& a, Other& b, F f) {
  f(a.encoder_loss, b.encoder_loss);
  f(a.fid, b.fid);
  f(a.fid_reconstruction, b.fid_reconstruction);
  f(a.fid_stream_reconstruction, b.fid_stream_reconstruction);
  f(a.fid_floor_views, b.fid_floor_views);
  f(a.fid_floor_time, b.fid_floor_time);
  f(a.fid_floor_sampled, b.fid_floor_sampled);
  f(a.fid_floor_sampled_segment, b.fid_floor_sampled_segment);
  f(a.diversity_real, b.diversity_real);
  f(a.diversity_generated, b.diversity_generated);
  f(a.precision, b.precision);
  f(a.recall, b.recall);
  f(a.precision_floor_time, b.precision_floor_time);
  f(a.recall_floor_time, b.recall_floor_time);
}

// Each figure's mean over the encoders (the lists element by element:
// every encoder scores the same motions and segments).
GeneratorFeatureFigures MeanFigures(
    const std::vector<GeneratorFeatureFigures>& by_encoder) {
  GeneratorFeatureFigures mean = by_encoder.front();
  for (size_t e = 1; e < by_encoder.size(); ++e) {
    const GeneratorFeatureFigures& other = by_encoder[e];
    ForEachScalarFigure(mean, other,
                        [](double& sum, double value) { sum += value; });
    for (size_t m = 0; m < mean.recall_by_motion.size(); ++m)
      mean.recall_by_motion[m].second += other.recall_by_motion[m].second;
    for (size_t k = 0; k < mean.fid_by_time_segment.size(); ++k)
      mean.fid_by_time_segment[k] += other.fid_by_time_segment[k];
  }
  const double count = static_cast<double>(by_encoder.size());
  ForEachScalarFigure(mean, mean,
                      [count](double& sum, double) { sum /= count; });
  for (auto& [motion, recall] : mean.recall_by_motion) recall /= count;
  for (double& segment_fid : mean.fid_by_time_segment) segment_fid /= count;
  return mean;
}

using SequenceSet = std::vector<GenSequence>;

// What every encoder scores, prepared once: the real and generated
// windows, and sets of sequences windowed as they are scored (the sampled
// floors' stretches would hold gigabytes of windows at 400 generations).
struct ScoredSets {
  torch::Tensor held_apart_windows, real_windows, reconstructed_windows,
      generated_windows;
  SequenceSet view_halves[2], time_halves[2];
  SequenceSet streamed, generated;
  std::vector<SequenceSet> floor_stretches;          // one set per draw
  std::vector<SequenceSet> segment_floor_stretches;  // the same, per segment
  std::vector<SequenceSet> segments;  // the generations' k-th parts
  std::vector<std::pair<std::string, SequenceSet>> motions;  // those holding
                                                             // a window
};

// The feature figures of one encoder, trained with `seed` on the
// held-apart windows.
GeneratorFeatureFigures ScoreInFeatures(
    const ScoredSets& sets, int frame_size,
    const std::function<torch::Tensor(const SequenceSet&)>& windows_of,
    const GeneratorEvalOptions& options, uint64_t seed) {
  GeneratorFeatureFigures figures;
  FeatureEncoderOptions encoder_options;
  encoder_options.window_frames = options.window_frames;
  encoder_options.steps = options.encoder_steps;
  FeatureEncoder encoder =
      TrainFeatureEncoder(sets.held_apart_windows, frame_size, encoder_options,
                          seed, &figures.encoder_loss);
  auto features_of = [&](const SequenceSet& sequences) {
    return EncodeWindows(encoder, windows_of(sequences));
  };
  auto fid_against = [](const Eigen::MatrixXd& features,
                        const FeatureGaussian& reference) {
    return FrechetDistance(FitFeatureGaussian(features), reference);
  };

  // The real features, and the floors: the real sequences in two halves by
  // view and in two halves in time; as many real stretches as generations.
  const Eigen::MatrixXd real_features =
      EncodeWindows(encoder, sets.real_windows);
  const FeatureGaussian real_gaussian = FitFeatureGaussian(real_features);
  figures.fid_floor_views =
      fid_against(features_of(sets.view_halves[0]),
                  FitFeatureGaussian(features_of(sets.view_halves[1])));
  const Eigen::MatrixXd first_half = features_of(sets.time_halves[0]),
                        second_half = features_of(sets.time_halves[1]);
  figures.fid_floor_time =
      fid_against(first_half, FitFeatureGaussian(second_half));
  const PrecisionRecall halves =
      ManifoldPrecisionRecall(first_half, second_half, options.neighbours);
  figures.precision_floor_time = halves.precision;
  figures.recall_floor_time = halves.recall;
  auto sampled_floor = [&](const std::vector<SequenceSet>& draws) {
    double sum = 0.0;
    for (const SequenceSet& stretches : draws)
      sum += fid_against(features_of(stretches), real_gaussian);
    return draws.empty() ? 0.0 : sum / draws.size();
  };
  figures.fid_floor_sampled = sampled_floor(sets.floor_stretches);
  figures.fid_floor_sampled_segment =
      sampled_floor(sets.segment_floor_stretches);

  // The tokenizer alone, and the streaming decoder alone.
  figures.fid_reconstruction = fid_against(
      EncodeWindows(encoder, sets.reconstructed_windows), real_gaussian);
  figures.fid_stream_reconstruction =
      fid_against(features_of(sets.streamed), real_gaussian);

  // The generations: FID, coverage (and each motion's windows alone on the
  // generated manifold: which motions they leave out), diversity, and each
  // time segment.
  const Eigen::MatrixXd generated_features =
      EncodeWindows(encoder, sets.generated_windows);
  figures.fid = fid_against(generated_features, real_gaussian);
  // ManifoldPrecisionRecall's two shares, the generated radii found once
  // (the longest step at 400 generations) for the recall by motion too.
  const Eigen::VectorXd generated_radii =
      KthNeighbourDistances(generated_features, options.neighbours);
  figures.precision = ShareWithinRadii(
      generated_features, real_features,
      KthNeighbourDistances(real_features, options.neighbours));
  figures.recall =
      ShareWithinRadii(real_features, generated_features, generated_radii);
  for (const auto& [motion, sequences] : sets.motions) {
    figures.recall_by_motion.push_back(
        {motion, ShareWithinRadii(features_of(sequences), generated_features,
                                  generated_radii)});
  }
  figures.diversity_real = MeanPairDistance(real_features, 300, options.seed);
  figures.diversity_generated =
      MeanPairDistance(generated_features, 300, options.seed);
  for (const SequenceSet& segment : sets.segments)
    figures.fid_by_time_segment.push_back(
        fid_against(features_of(segment), real_gaussian));
  return figures;
}

}  // namespace

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
  if (options.encoders < 1)
    throw ConfigError("gen eval: encoders must be at least 1");
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
  const std::function<torch::Tensor(const SequenceSet&)> windows_of =
      [&](const SequenceSet& sequences) {
        return DatasetWindows(sequences, frame_size, options.window_frames,
                              options.stride_frames, tokenizer.mean,
                              tokenizer.std);
      };
  GeneratorEvalResult result;
  ScoredSets sets;

  // 1. The real and the held-apart windows; the real sequences in two
  // halves by view and in two halves in time; each motion's sequences.
  sets.held_apart_windows = windows_of(held_apart.sequences);
  result.held_apart_windows = static_cast<int>(sets.held_apart_windows.size(0));
  sets.real_windows = windows_of(real.sequences);
  result.real_windows = static_cast<int>(sets.real_windows.size(0));
  for (size_t i = 0; i < real.sequences.size(); ++i)
    sets.view_halves[i % 2].push_back(real.sequences[i]);
  for (const GenSequence& sequence : real.sequences) {
    auto [first, second] = SplitSequenceInTime(sequence, frame_size);
    sets.time_halves[0].push_back(std::move(first));
    sets.time_halves[1].push_back(std::move(second));
  }
  {
    std::map<std::string, SequenceSet> by_motion;
    for (const GenSequence& sequence : real.sequences)
      by_motion[sequence.name.substr(0, sequence.name.find('/'))].push_back(
          sequence);
    for (auto& [motion, sequences] : by_motion) {
      bool has_window = false;
      for (const GenSequence& sequence : sequences)
        has_window |= sequence.num_frames >= options.window_frames;
      if (has_window) sets.motions.push_back({motion, std::move(sequences)});
    }
  }

  // 2. The tokenizer alone: every real window encoded and decoded (windows
  // of the length it was trained on; decoding whole sequences at once was
  // 3x worse on the local pose: the network leans on the windows' edges).
  {
    torch::NoGradGuard no_grad;
    sets.reconstructed_windows =
        tokenizer.model->Decode(tokenizer.model->Encode(sets.real_windows));
    const torch::Tensor error =
        (sets.reconstructed_windows - sets.real_windows).abs() * tokenizer.std;
    const int pose = RootStepColumn(frame_size);  // the local pose before it
    result.reconstruction_pose_error =
        error.narrow(2, 0, pose).mean().item<double>();
    result.reconstruction_root_error =
        error.narrow(2, pose, 2).mean().item<double>();
    result.reconstruction_scale_error =
        error.narrow(2, pose + 2, 1).mean().item<double>();
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
  auto count_jumps = [&](const SequenceSet& sequences, int seam_frames) {
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
    for (size_t i = 0; i < code_sequences.size(); ++i) {
      MotionStream stream(tokenizer, code_sequences[i], options.generation);
      const int64_t frames = stream.frames_available();
      std::vector<float> rows;
      while (static_cast<int64_t>(rows.size()) < frames * frame_size)
        stream.Next(&rows);
      sets.streamed.push_back({"streamed/" + std::to_string(i),
                               static_cast<int>(frames), std::move(rows)});
    }
    result.jumps_per_min_stream = count_jumps(sets.streamed, 0).per_min;
  }

  // The floors at the generations' sample size: as many real stretches as
  // generations, as long as a generation (and as a segment), drawn among
  // the sequences that hold a window, as the real windows are (a
  // once-played kick of 46 frames holds none).
  const int generation_frames =
      static_cast<int>(std::lround(options.seconds * real.fps));
  for (int d = 0; d < options.floor_draws; ++d) {
    const uint64_t draw_seed = options.seed + 1000 + d;
    sets.floor_stretches.push_back(DrawRealStretches(
        real.sequences, frame_size, generation_frames, options.generations,
        options.window_frames, draw_seed));
    if (options.time_segments > 1) {
      sets.segment_floor_stretches.push_back(DrawRealStretches(
          real.sequences, frame_size, segment_frames, options.generations,
          options.window_frames, draw_seed));
    }
  }

  // 3. The generations, timed on one thread.
  const int threads = torch::get_num_threads();
  torch::set_num_threads(1);
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
    sets.generated.push_back({"generated/" + std::to_string(g + 1),
                              motion.num_frames, std::move(motion.rows)});
  }
  torch::set_num_threads(threads);
  result.realtime_factor = generated_s / std::max(1e-9, generation_s);
  sets.generated_windows = windows_of(sets.generated);
  result.generated_windows = static_cast<int>(sets.generated_windows.size(0));
  if (options.time_segments > 1) {
    sets.segments.resize(options.time_segments);
    for (const GenSequence& sequence : sets.generated) {
      SequenceSet parts =
          CutSequenceInTime(sequence, frame_size, options.time_segments);
      for (int k = 0; k < options.time_segments; ++k)
        sets.segments[k].push_back(std::move(parts[k]));
    }
  }

  // The figures that need no features: jumps and placement drift.
  {
    const Jumps generated_jumps =
        count_jumps(sets.generated, options.generation.decoding.emit_codes *
                                        tokenizer.model->frames_per_token());
    result.jumps_per_min_generated = generated_jumps.per_min;
    result.jump_share_at_seams = generated_jumps.share_at_seams;
  }
  auto rms_drift = [&](const SequenceSet& sequences, double* log_scale,
                       double* root) {
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
  rms_drift(sets.generated, &result.drift_log_scale_generated,
            &result.drift_root_generated);
  rms_drift(sets.floor_stretches.front(), &result.drift_log_scale_real,
            &result.drift_root_real);

  // 4. The figures in each encoder's features, and their means.
  for (int e = 0; e < options.encoders; ++e) {
    result.by_encoder.push_back(ScoreInFeatures(sets, frame_size, windows_of,
                                                options, options.seed + e));
  }
  static_cast<GeneratorFeatureFigures&>(result) =
      MeanFigures(result.by_encoder);
  return result;
}

}  // namespace m2d
