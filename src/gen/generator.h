// gen: using a trained generator — generating X^can, and measuring it: FID
// of generated against real 2D motion in the features of an encoder
// trained on held-apart motion, the real-against-real floor, diversity and
// speed. This header does not include LibTorch.
#ifndef MIMIC2D_GEN_GENERATOR_H_
#define MIMIC2D_GEN_GENERATOR_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "gen/gen_config.h"
#include "gen/motion_dataset.h"

namespace m2d {

// The config a generator run was trained with (embedded in its
// tokenizer.pt). InputError naming the file when it cannot be read.
GenConfig ReadGeneratorConfig(const std::string& run_dir);
// The config its prior was trained with (prior.pt's): the same data and
// tokenizer, and the prior's own settings, which a prior retrained on a
// kept tokenizer may have changed.
GenConfig ReadPriorConfig(const std::string& run_dir);

struct GeneratedMotion {
  std::vector<float> rows;  // num_frames rows of X^can (CanonicalFeatures)
  int num_frames = 0;
  double fps = 30.0;
  int num_codes = 0;          // codes drawn from the prior
  double generation_s = 0.0;  // wall time of the generation itself
};

// `seconds` of motion streamed from the run's prior and tokenizer
// (gen/motion_stream.h). `generation.view`: which of the data's views a
// prior conditioned on the view generates (-1 for one that is not;
// GenerationView picks it).
GeneratedMotion GenerateMotion(const std::string& run_dir, double seconds,
                               const GenerationOptions& generation);

// The condition a run's prior generates for a camera at `azimuth_deg`,
// `elevation_deg`: the nearest of the data's views when it is conditioned
// on the view (and `motion`, an index into data.motions, when it is
// conditioned on the motion too), else -1. ConfigError for a motion the
// prior does not know.
int GenerationView(const GenConfig& config, double azimuth_deg,
                   double elevation_deg, int motion = 0);

struct GeneratorEvalOptions {
  // Independent streams (seeds 1..N); a prior conditioned on the view
  // generates generation g in view g mod V, as evenly as the data holds
  // its views.
  int generations = 10;
  double seconds = 60.0;         // per generation
  GenerationOptions generation;  // its seed and view are set per generation
  int window_frames = 64;        // feature windows
  int stride_frames = 16;
  int64_t encoder_steps = 3000;
  // Feature encoders trained, seeds seed, seed + 1, ...; every feature
  // figure is the mean over them. One encoder's figures move with how it
  // happened to train: the same seed on another CPU's kernels trains
  // another encoder, and the FID's ratio to its floor moved 1.79 -> 2.06
  // between two machines, and between five seeds on one machine over 100
  // generations from 1.70 to 2.20 (docs/generation.md, section 5).
  int encoders = 5;
  uint64_t seed = 1;  // the first encoder's initialization and batches
  // Each generation is also cut into this many equal parts in time, and
  // the windows of each part scored alone: a prior that drifts away from
  // the data as its context slides scores worse in the later parts.
  int time_segments = 4;
  // Draws of real stretches averaged in the sampled floors (below).
  int floor_draws = 5;
  int neighbours = 3;  // k of precision and recall (the paper's default)
};

// The figures read in a feature encoder's features: one set per encoder.
struct GeneratorFeatureFigures {
  double encoder_loss = 0.0;  // reconstruction MSE at the end
  double fid = 0.0;           // generated vs real
  // The tokenizer alone: every real window encoded and decoded.
  double fid_reconstruction = 0.0;
  // The streaming decoder alone: every real sequence's codes, encoded whole
  // as the prior learns them, decoded as a generation's are
  // (MotionStream's replay; options.generation's decoding and anchor). The
  // floor a perfect prior's generations would score.
  double fid_stream_reconstruction = 0.0;
  // Real vs real, two floors: the sequences' views in two halves
  // (alternating; every motion and frame in both: how far the features
  // move with the view alone) and every sequence cut in two in time (every
  // motion and view in both, no frame in both: real motion that is not the
  // same motion, the floor a generator of new motion is held to).
  double fid_floor_views = 0.0, fid_floor_time = 0.0;
  // The floor at the generations' own sample size: as many real stretches
  // as generations, each as long as a generation (all of a shorter
  // sequence; DrawRealStretches), against every real window; the mean of
  // `floor_draws` draws. A generator replaying real motion scores this
  // with so few generations: 100 draws see about 80 of the long walks' 216
  // sequences, and the windows of one stretch are alike. `_segment`:
  // stretches as long as one time segment, the floor of
  // `fid_by_time_segment` (approximate: stretches from random starts draw a
  // sequence's first and last seconds less often than its middle).
  double fid_floor_sampled = 0.0, fid_floor_sampled_segment = 0.0;
  double diversity_real = 0.0;  // mean feature distance of random pairs
  double diversity_generated = 0.0;
  // Improved precision and recall (eval/metrics.h) of the generated windows
  // against the real ones, and of the second halves in time against the
  // first (what real motion that is not the same motion scores); the
  // recall of each motion's windows alone (the part of a sequence's name
  // before its first '/'), for the motions that hold a window.
  double precision = 0.0, recall = 0.0;
  double precision_floor_time = 0.0, recall_floor_time = 0.0;
  std::vector<std::pair<std::string, double>> recall_by_motion;
  // FID vs real of the generated windows in each time segment (the k-th
  // part of every generation; equal window counts, so comparable with each
  // other, not with `fid`, which has more windows and less bias).
  std::vector<double> fid_by_time_segment;
};

// The figures of `gen eval`: the feature figures (the base) are the means
// over the encoders, `by_encoder` each encoder's own.
struct GeneratorEvalResult : GeneratorFeatureFigures {
  int real_windows = 0, held_apart_windows = 0, generated_windows = 0;
  std::vector<GeneratorFeatureFigures> by_encoder;
  // The tokenizer's reconstructions of the real windows: mean |error| per
  // channel group of X^can (body-scale units).
  double reconstruction_pose_error = 0.0, reconstruction_root_error = 0.0,
         reconstruction_scale_error = 0.0;
  // Placement drift over a generation (PlacementDriftOf), root mean square
  // over the generations, and over as many real stretches of the same
  // length: the change of log scale, and the root's displacement (units of
  // the first frame's scale). The FID's windows see steps, not where they
  // add up to; a tracker behind a following camera sees the sum.
  double drift_log_scale_generated = 0.0, drift_log_scale_real = 0.0;
  double drift_root_generated = 0.0, drift_root_real = 0.0;
  // Jumps (LargestPoseSteps): frames whose largest keypoint step passes
  // the real data's 99.9th percentile of it (`jump_threshold`, body
  // scales), per minute, in the generations, in the real codes decoded as
  // a stream and in the real motion itself (0.1 % of its frames by the
  // threshold's definition: 1.8 a minute at 30 fps); and the share of the
  // generations' jumps on the first frame of a decoding (every emit_codes
  // codes: the seams).
  double jump_threshold = 0.0;
  double jumps_per_min_generated = 0.0, jumps_per_min_stream = 0.0,
         jumps_per_min_real = 0.0;
  double jump_share_at_seams = 0.0;
  double realtime_factor = 0.0;  // generated seconds per second of CPU
                                 // time, one LibTorch thread
  std::string BriefReport() const;
};

// Outline: the real windows (the generator's own dataset, rebuilt from its
// config) and the held-apart windows (`held_apart`: motions it never saw)
// in the tokenizer's normalization; the tokenizer's reconstructions, the
// real codes decoded as a stream and `generations` generated streams; then
// for each of `encoders` encoders trained on the held-apart windows, the
// features of the real windows, of two pairs of halves of them (by view
// and by time), of the reconstructions and of the generations, and from
// them FIDs, coverage and diversities; their means. `run_dir` holds
// tokenizer.pt and prior.pt.
GeneratorEvalResult EvaluateGenerator(const std::string& run_dir,
                                      const GenDataset& real,
                                      const GenDataset& held_apart,
                                      const GeneratorEvalOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_GEN_GENERATOR_H_
