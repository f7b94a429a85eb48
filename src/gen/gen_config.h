// gen: the generator's settings — data, tokenizer (VQ-VAE), prior (GPT)
// and run — each a typed section of one YAML file (configs/gen_*.yaml).
// This header does not include LibTorch.
#ifndef MIMIC2D_GEN_GEN_CONFIG_H_
#define MIMIC2D_GEN_GEN_CONFIG_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/settings.h"
#include "gen/motion_dataset.h"

namespace m2d {

// What the generator learns from: 3D motions projected into many views.
struct GenDataOptions {
  // DeepMimic .txt motions (the humanoid skeleton) or CMU .bvh files,
  // relative to the working directory as every path of a config.
  std::vector<std::string> motions = {
      "assets/motions/deepmimic/humanoid3d_walk.txt"};
  double fps = 30.0;  // frame rate of the 2D sequences
  // A looping motion (DeepMimic's walk cycle) is repeated to at least this
  // long, so that the prior sees cycles follow each other.
  double loop_to_s = 20.0;
  // What the cycle's net heading turn does across the repeats: the
  // DeepMimic walk turns about 100 deg in 20 s when it accumulates; a
  // prior over 4-s windows cannot tell how far a sequence has turned, so
  // its generations turn back and forth and jump between headings.
  LoopHeading loop_heading = LoopHeading::kAccumulate;
  GenViewOptions views;

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("motions", self.motions, Range::Any(),
      "3D motions (DeepMimic .txt or CMU .bvh)");
    v("fps", self.fps, Range::Closed(1, 240), "frame rate of the 2D (Hz)");
    v("loop_to_s", self.loop_to_s, Range::Closed(0, 3600),
      "looping motions are repeated to at least this long (s)");
    v("loop_heading", self.loop_heading, Range::Any(),
      "a cycle's net heading turn across the repeats: accumulate (DeepMimic's "
      "wrap) or straight (spread back over the cycle)");
    v("num_azimuths", self.views.num_azimuths, Range::Closed(1, 360),
      "views per elevation, spread over 360 degrees");
    v("elevations_deg", self.views.elevations_deg, Range::Open(-80, 80),
      "camera elevations (deg)");
    v("distance_m", self.views.distance_m, Range::Above(0.1),
      "camera to subject (m)");
    v("focal_px", self.views.focal_px, Range::Above(0), "focal length (px)");
    v("follow_smoothing_s", self.views.follow_smoothing_s, Range::Closed(0, 60),
      "the dolly follows the subject's ground path averaged over this (s); "
      "0: the root itself");
  }
  void Validate() const;  // throws ConfigError
};

// The tokenizer: a 1D-convolutional VQ-VAE over X^can (T2M-GPT's design at
// the paper's sizes: codebook 512 x 128).
struct VqVaeOptions {
  int num_codes = 512;          // K, the paper's codebook size
  int code_size = 128;          // D, the paper's embedding size
  int width = 128;              // channels of the convolutions
  int down_levels = 2;          // each halves time: 2^levels frames per token
  int residual_depth = 3;       // residual blocks per level (dilations 9, 3, 1)
  double ema_decay = 0.99;      // codebook moving average
  double commit_weight = 0.02;  // beta on |z - sg(q)|^2
  double absolute_weight = 1.0;  // omega on |G^-1(X) - G^-1(X^)| (paper)
  double velocity_weight = 0.5;  // on frame differences of the local pose
  int window_frames = 64;        // training windows (multiple of 2^levels)
  int batch_size = 64;
  double learning_rate = 2e-4;  // AdamW
  int64_t steps = 20000;        // gradient steps

  int frames_per_token() const { return 1 << down_levels; }

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("num_codes", self.num_codes, Range::Closed(2, 65536), "codebook size K");
    v("code_size", self.code_size, Range::Closed(1, 4096),
      "code embedding size D");
    v("width", self.width, Range::Closed(1, 4096), "convolution channels");
    v("down_levels", self.down_levels, Range::Closed(0, 6),
      "time halvings: 2^levels frames per token");
    v("residual_depth", self.residual_depth, Range::Closed(0, 8),
      "dilated residual blocks per level");
    v("ema_decay", self.ema_decay, Range::Open(0, 1),
      "codebook moving-average decay");
    v("commit_weight", self.commit_weight, Range::AtLeast(0),
      "commitment loss weight (beta)");
    v("absolute_weight", self.absolute_weight, Range::AtLeast(0),
      "weight of the absolute-coordinate loss (omega)");
    v("velocity_weight", self.velocity_weight, Range::AtLeast(0),
      "weight of the local-pose velocity loss");
    v("window_frames", self.window_frames, Range::Closed(1, 100000),
      "frames per training window");
    v("batch_size", self.batch_size, Range::Closed(1, 100000),
      "windows per gradient step");
    v("learning_rate", self.learning_rate, Range::Above(0), "AdamW rate");
    v("steps", self.steps, Range::Closed(0, 1e9), "gradient steps");
  }
  void Validate() const;  // throws ConfigError
};

// The prior: a GPT-style causal transformer over the tokens (the paper's 4
// layers, 4 heads, embedding 128).
struct GptOptions {
  int num_layers = 4;
  int num_heads = 4;
  int embedding = 128;
  int context_tokens = 32;  // attention window (tokens); also the sliding
                            // context of endless generation
  double dropout = 0.1;
  // Each input token is replaced by a random code with probability
  // 1 - keep (T2M-GPT's corruption), so that sampling recovers from its own
  // unlikely draws.
  double keep_probability = 0.9;
  // Every window opens with a token naming the view its sequence is seen
  // from (T2M-GPT's slot 0, which holds its text): generation is asked for
  // a view and cannot drift into another one.
  bool condition_on_view = false;
  // The token names the motion as well (one per view and motion of
  // data.motions): a stream stays in the motion it began as, and the
  // generations are spread over the motions as the data's frames are
  // (docs/generation.md, "Coverage"). Needs condition_on_view.
  bool condition_on_motion = false;
  int batch_size = 64;
  double learning_rate = 2e-4;  // AdamW
  int64_t steps = 20000;

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("num_layers", self.num_layers, Range::Closed(1, 64),
      "transformer blocks");
    v("num_heads", self.num_heads, Range::Closed(1, 64), "attention heads");
    v("embedding", self.embedding, Range::Closed(1, 4096),
      "token embedding size (a multiple of num_heads)");
    v("context_tokens", self.context_tokens, Range::Closed(2, 4096),
      "attention window in tokens");
    v("dropout", self.dropout, Range::Closed(0, 0.9), "dropout rate");
    v("keep_probability", self.keep_probability, Range::Closed(0, 1),
      "input tokens kept (others replaced by random codes)");
    v("condition_on_view", self.condition_on_view, Range::Any(),
      "windows open with a token naming the data's view");
    v("condition_on_motion", self.condition_on_motion, Range::Any(),
      "the token names the view and the motion (needs condition_on_view)");
    v("batch_size", self.batch_size, Range::Closed(1, 100000),
      "token windows per gradient step");
    v("learning_rate", self.learning_rate, Range::Above(0), "AdamW rate");
    v("steps", self.steps, Range::Closed(0, 1e9), "gradient steps");
  }
  void Validate() const;  // throws ConfigError
};

// How codes are drawn from the prior.
struct SamplingOptions {
  double temperature = 1.0;  // > 0; lower is greedier
  int top_k = 0;             // sample among the k likeliest codes (0: all)
  // Codes kept when the prior's full context slides: generation restarts
  // its attention from the last `kept_context_tokens` codes (0: half the
  // context). More keeps more of the motion's past in view after each
  // restart and restarts more often (a pass over the kept codes each).
  int kept_context_tokens = 0;
  void Validate() const;  // throws ConfigError
};

// How the stream decodes codes into frames (gen/motion_stream.h).
struct StreamDecoding {
  // Codes the decoder sees per step. Its receptive field spans about ±15
  // codes (dilations 9, 3, 1 at the code rate); more costs time, fewer
  // makes the seams between codes show.
  int context_codes = 16;
  // Codes decoded after the one emitted (latency, 4 frames each): the
  // decoder is least sure at the window's open edge. 2 since 2026-12-07
  // (was 1): with blend_seams the seams' overlap is the lookahead's frames,
  // and 8 frames blend the styles' seams to their real 2D's speeds.
  int lookahead_codes = 2;
  // Codes whose frames one decoding emits: the decoder runs once per this
  // many codes (its cost shared by their frames) at this many codes' more
  // latency. They sit just before the lookahead in the window.
  int emit_codes = 4;
  // Each decoding is its own pass, and two passes disagree where they meet:
  // the last code one emits had only the lookahead after it, the next
  // pass's first code has more. Unblended, every seam (each emit_codes
  // codes) jumps: on the long walks' styles 33-41 frames a minute moved a
  // keypoint faster than any frame of their real 2D, all of them at seams
  // (docs/generation.md, "Seams"). Blended, the next pass's first
  // lookahead frames fade in from what the previous pass decoded for them
  // (weights (i + 1) / (n + 1) on the new pass, n = the overlap's frames).
  bool blend_seams = true;
};

// One generation: how its codes are drawn and decoded, its seed and view,
// and how its placement is held.
struct GenerationOptions {
  SamplingOptions sampling;
  StreamDecoding decoding;
  uint64_t seed = 1;
  int view = -1;  // the data's view to generate (a conditioned prior's)
  // PlacementAnchor's return time (s): the stream's log scale and root are
  // pulled back toward the first frame's, as the data's following cameras
  // hold them (0: off; the steps as the prior draws them). At 20 s the
  // long walks' generations wander over 120 s as far as real stretches do
  // (log scale 0.05 against 0.06, root 0.21 against 0.34 body scales; 0.22
  // and 1.1 unanchored; docs/generation.md, section 5).
  double placement_return_s = 20.0;
};

// Where and how a run goes.
struct GenRunOptions {
  std::string run_dir = "runs/gen";  // tokenizer.pt, prior.pt, logs
  uint64_t seed = 1;
  double checkpoint_minutes = 5.0;
  int torch_threads = 2;
  // Probe 1 thread against torch_threads while training and keep the
  // faster (rl/speed_tuner.h), as the PPO trainer's agent setting does: two
  // threads collapse when another process competes for the cores.
  bool adapt_torch_threads = false;

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("run_dir", self.run_dir, Range::Any(),
      "checkpoints and logs (relative to the working directory)");
    v("seed", self.seed, Range::Any(), "seed of initialization and batches");
    v("checkpoint_minutes", self.checkpoint_minutes, Range::Above(0),
      "minutes between checkpoints");
    v("torch_threads", self.torch_threads, Range::Closed(1, 256),
      "LibTorch threads");
    v("adapt_torch_threads", self.adapt_torch_threads, Range::Any(),
      "probe 1 thread against torch_threads while training and keep the "
      "faster (re-probed as the load changes; needs torch_threads >= 2)");
  }
};

struct GenConfig {
  std::string source_path;  // the YAML file
  GenDataOptions data;
  VqVaeOptions tokenizer;
  GptOptions prior;
  GenRunOptions run;

  // View tokens of the prior's vocabulary: the data's views when it is
  // conditioned on them, else 0.
  int prior_views() const {
    return prior.condition_on_view ? data.views.num_views() : 0;
  }
  // Motions the condition token names: data.motions when conditioned on
  // them, else 1 (the token names the view alone).
  int prior_motions() const {
    return prior.condition_on_motion ? static_cast<int>(data.motions.size())
                                     : 1;
  }
  // Condition tokens of the prior's vocabulary, and the one of a view and
  // motion (motion 0 when not conditioned on it).
  int prior_conditions() const { return prior_views() * prior_motions(); }
  int PriorCondition(int view, int motion) const {
    return view + prior_views() * (prior.condition_on_motion ? motion : 0);
  }
  void Validate() const;  // throws ConfigError naming the setting
};

// Reads a config; InputError naming the file and key for unknown keys,
// wrong types, out-of-range values.
GenConfig LoadGenConfig(const std::string& yaml_path);
// Every setting written out (what a checkpoint embeds) and read back.
std::string GenConfigToYaml(const GenConfig& config);
GenConfig LoadGenConfigText(const std::string& yaml_text,
                            const std::string& source);
// The reference table of every setting (Markdown).
std::string GenSettingsReference();

}  // namespace m2d

#endif  // MIMIC2D_GEN_GEN_CONFIG_H_
