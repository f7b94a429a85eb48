#include "gen/gen_trainer.h"

#include <ATen/CPUGeneratorImpl.h>
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "common/file_io.h"
#include "common/pauses.h"
#include "gen/gen_checkpoint.h"
#include "gen/gpt.h"
#include "gen/vqvae.h"
#include "rl/speed_tuner.h"

namespace m2d {

const char* SettingName(GenStage stage) {
  return stage == GenStage::kTokenizer ? "tokenizer" : "prior";
}

std::string GenTrainSummary::BriefReport() const {
  // NaN: the stage took no step in this run (already trained).
  auto figure = [](const char* name, double value, const char* unit) {
    std::ostringstream text;
    if (std::isnan(value)) {
      text << "no step this run";
    } else {
      text << name << " " << value << unit;
    }
    return text.str();
  };
  std::ostringstream out;
  out << (interrupted ? "interrupted" : "finished") << ": tokenizer "
      << tokenizer_steps << " steps (" << figure("loss", tokenizer_loss, "")
      << "), prior " << prior_steps << " steps ("
      << figure("cross-entropy", prior_loss, " nats") << ")\n"
      << "  checkpoints: " << tokenizer_path << ", " << prior_path << "\n";
  return out.str();
}

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A stage's CSV log: one row per report, the step first. On resume, rows
// past the checkpoint's step (and rows torn by a kill) are dropped.
class StageLog {
 public:
  StageLog(std::string path, std::string header, bool resume, int64_t step)
      : path_(std::move(path)), header_(std::move(header)) {
    const size_t columns = Columns(header_);
    std::ostringstream kept;
    kept << header_ << "\n";
    if (resume) {
      std::ifstream in(path_);
      std::string line;
      std::getline(in, line);
      while (std::getline(in, line)) {
        if (Columns(line) == columns && std::atoll(line.c_str()) <= step)
          kept << line << "\n";
      }
    }
    WriteFileAtomic(path_, kept.str());
    out_.open(path_, std::ios::app);
    if (!out_) throw InputError(path_, "cannot open the log for appending");
  }

  void Append(const std::string& row) {
    out_ << row << "\n";
    out_.flush();
    if (!out_) throw InputError(path_, "cannot write the log (disk full?)");
  }

 private:
  static size_t Columns(const std::string& line) {
    return static_cast<size_t>(std::count(line.begin(), line.end(), ',')) + 1;
  }
  std::string path_, header_;
  std::ofstream out_;
};

// Normalized windows [B, W, C] of the dataset: a sequence drawn with
// probability proportional to its frames, a start uniform in it. A sequence
// shorter than W is held at its last pose (zero deltas) to fill the window.
torch::Tensor SampleWindows(const GenDataset& dataset, int window, int batch,
                            const torch::Tensor& mean, const torch::Tensor& std,
                            torch::Generator& generator) {
  const int frame_size = dataset.frame_size;
  std::vector<double> weights;
  for (const GenSequence& sequence : dataset.sequences)
    weights.push_back(sequence.num_frames);
  torch::Tensor chosen = torch::multinomial(
      torch::tensor(weights, torch::kDouble), batch, true, generator);
  torch::Tensor windows = torch::empty({batch, window, frame_size});
  for (int b = 0; b < batch; ++b) {
    const GenSequence& sequence = dataset.sequences[chosen[b].item<int64_t>()];
    const int64_t starts = std::max(1, sequence.num_frames - window + 1);
    const int64_t start =
        torch::randint(starts, {1}, generator, torch::kLong).item<int64_t>();
    float* out = windows[b].data_ptr<float>();
    for (int t = 0; t < window; ++t) {
      const int64_t frame =
          std::min<int64_t>(start + t, sequence.num_frames - 1);
      const float* row = sequence.features.data() + frame * frame_size;
      std::copy(row, row + frame_size, out + t * frame_size);
      if (start + t >= sequence.num_frames) {  // held: no root or scale step
        std::fill(out + t * frame_size + RootStepColumn(frame_size),
                  out + (t + 1) * frame_size, 0.0f);
      }
    }
  }
  return (windows - mean) / std;
}

// Linear warm-up over the first 5 % of steps (at most 1000), then the full
// rate until 2/3 of the steps, then a tenth of it (T2M-GPT's schedule,
// shortened).
double ScheduledRate(double rate, int64_t step, int64_t steps) {
  const double warmup = std::min<double>(1000.0, 0.05 * steps);
  if (step < warmup) return rate * (step + 1) / warmup;
  return step < steps * 2 / 3 ? rate : 0.1 * rate;
}

void SetRate(torch::optim::Optimizer& optimizer, double rate) {
  for (auto& group : optimizer.param_groups())
    static_cast<torch::optim::AdamWOptions&>(group.options()).lr(rate);
}

// Reports and checkpoints at most this often.
constexpr double kReportSeconds = 2.0;

struct StageClock {
  Clock::time_point started = Clock::now();
  Clock::time_point last_report = Clock::now();
  Clock::time_point last_checkpoint = Clock::now();
  double seconds_before = 0.0;  // resumed stages' earlier time
  double seconds() const { return seconds_before + SecondsSince(started); }
};

// What both stages share.
struct StageContext {
  const GenConfig& config;
  const GenDataset& dataset;
  const std::atomic<bool>* stop;
  const std::function<void(const GenProgress&)>& on_progress;
  torch::Tensor mean, std;  // [C], the dataset's normalization

  bool stop_requested() const { return stop != nullptr && stop->load(); }
  std::string RunFile(const char* name) const {
    return (std::filesystem::path(config.run.run_dir) / name).string();
  }
  // Report at the first step, every kReportSeconds and at the last step.
  static bool ReportDue(const GenProgress& progress, const StageClock& clock) {
    return progress.step == 1 || progress.step == progress.steps ||
           SecondsSince(clock.last_report) >= kReportSeconds;
  }
  bool CheckpointDue(const StageClock& clock) const {
    return SecondsSince(clock.last_checkpoint) >=
           60.0 * config.run.checkpoint_minutes;
  }
};

// LibTorch's thread count, step by step: run.torch_threads, or with
// run.adapt_torch_threads the faster of it and 1 thread as a SpeedTuner
// measures them (probes now and then, more often after a slowdown).
class StepThreads {
 public:
  explicit StepThreads(const GenRunOptions& run)
      : configured_(run.torch_threads) {
    if (run.adapt_torch_threads && configured_ >= 2)
      tuner_ = std::make_unique<SpeedTuner>(SpeedTunerOptions());
  }
  // Before a step: the threads it runs with, and its clock started.
  void Begin() {
    candidate_ = tuner_ ? tuner_->CandidateForNextIteration() : 0;
    torch::set_num_threads(Threads(candidate_));
    started_ = Clock::now();
    mark_ = MarkPauses();
  }
  // After it: its time to the tuner, unless a pause of the process or the
  // machine's sleep falls inside (common/pauses.h).
  void End() {
    if (!tuner_ || PausedBetween(mark_, MarkPauses())) return;
    tuner_->Record(candidate_, SecondsSince(started_));
  }
  // The chosen setting's threads (what the steps run with between probes).
  int chosen_threads() const { return Threads(tuner_ ? tuner_->chosen() : 0); }

 private:
  int Threads(int candidate) const { return candidate == 0 ? configured_ : 1; }

  int configured_;
  std::unique_ptr<SpeedTuner> tuner_;
  int candidate_ = 0;
  Clock::time_point started_;
  PauseMark mark_;
};

// The loop both stages share: until `steps` or a stop, the scheduled rate,
// one `step()`, a report when due (`report` fills the stage's figures into
// the progress and returns its log row), a checkpoint (`save`) when due and
// at the end. Returns the last reported loss.
template <typename Step, typename Report, typename Save>
double RunStage(const StageContext& context, GenStage stage, int64_t steps,
                double base_rate, torch::optim::Optimizer& optimizer,
                StageLog& log, GenStageState* state, Step step, Report report,
                Save save) {
  StageClock clock;
  clock.seconds_before = state->seconds;
  GenProgress progress;
  progress.stage = stage;
  progress.steps = steps;
  progress.loss = std::numeric_limits<double>::quiet_NaN();  // until a report
  auto checkpoint = [&] {
    clock.last_checkpoint = Clock::now();
    state->seconds = clock.seconds();
    save();
  };
  StepThreads threads(context.config.run);
  while (state->step < steps && !context.stop_requested()) {
    const double rate = ScheduledRate(base_rate, state->step, steps);
    SetRate(optimizer, rate);
    threads.Begin();
    step();
    threads.End();
    progress.step = ++state->step;
    if (StageContext::ReportDue(progress, clock)) {
      clock.last_report = Clock::now();
      progress.seconds = clock.seconds();
      progress.learning_rate = rate;
      progress.torch_threads = threads.chosen_threads();
      log.Append(report(&progress));
      if (context.on_progress) context.on_progress(progress);
    }
    if (context.CheckpointDue(clock)) checkpoint();
  }
  checkpoint();
  return progress.loss;
}

// Trains `model` on windows of the dataset up to tokenizer.steps (from
// its checkpoint when resuming); returns the last reported loss.
double TrainTokenizer(const StageContext& context, bool resume, VqVae& model,
                      GenStageState* state) {
  const VqVaeOptions& options = context.config.tokenizer;
  const int num_keypoints = context.dataset.layout->num_keypoints();
  const std::string path = context.RunFile(kTokenizerFile);
  torch::optim::AdamW optimizer(
      model->parameters(), torch::optim::AdamWOptions(options.learning_rate)
                               .betas({0.9, 0.99})
                               .weight_decay(0.0));
  torch::Generator generator =
      at::make_generator<at::CPUGeneratorImpl>(context.config.run.seed + 17);
  resume = resume && std::filesystem::exists(path);
  if (resume) {
    ResumeTokenizer(path, model, optimizer, state);
    if (state->generator_state.defined())
      generator.set_state(state->generator_state);
  }
  StageLog log(context.RunFile("tokenizer_log.csv"),
               "step,seconds,learning_rate,loss,canonical,absolute,velocity,"
               "commit,perplexity,used_codes,reset_codes",
               resume, state->step);
  VqVaeImpl::Output out;
  VqVaeLosses losses;
  model->train();
  // One step: a batch of windows, encode-quantize-decode (the codebook
  // follows its moving averages), the losses, AdamW.
  auto step = [&] {
    torch::Tensor batch =
        SampleWindows(context.dataset, options.window_frames,
                      options.batch_size, context.mean, context.std, generator);
    out = model->Forward(batch, &generator);
    losses =
        ComputeVqVaeLosses(out.reconstruction, batch, out.commit_loss,
                           context.mean, context.std, num_keypoints, options);
    optimizer.zero_grad();
    losses.total.backward();
    optimizer.step();
  };
  auto report = [&](GenProgress* p) {
    p->loss = losses.total.item<double>();
    p->canonical_loss = losses.canonical.item<double>();
    p->absolute_loss = losses.absolute.item<double>();
    p->velocity_loss = losses.velocity.item<double>();
    p->commit_loss = losses.commit.item<double>();
    p->perplexity = out.stats.perplexity;
    p->used_codes = out.stats.used_codes;
    p->reset_codes = out.stats.reset_codes;
    char row[512];
    std::snprintf(
        row, sizeof(row), "%lld,%.2f,%.3g,%.6g,%.6g,%.6g,%.6g,%.6g,%.2f,%d,%d",
        static_cast<long long>(p->step), p->seconds, p->learning_rate, p->loss,
        p->canonical_loss, p->absolute_loss, p->velocity_loss, p->commit_loss,
        p->perplexity, p->used_codes, p->reset_codes);
    return std::string(row);
  };
  auto save = [&] {
    state->generator_state = generator.get_state();
    SaveTokenizer(path, context.config, model, context.mean, context.std,
                  &optimizer, *state);
  };
  return RunStage(context, GenStage::kTokenizer, options.steps,
                  options.learning_rate, optimizer, log, state, step, report,
                  save);
}

// Trains `model` on windows of the token sequences (each seen from its
// view of `views`) up to prior.steps; returns the last reported
// cross-entropy.
double TrainPrior(const StageContext& context, bool resume,
                  const std::vector<std::vector<int64_t>>& token_sequences,
                  const std::vector<int>& views, Gpt& model,
                  GenStageState* state) {
  const GptOptions& options = context.config.prior;
  const std::string path = context.RunFile(kPriorFile);
  torch::optim::AdamW optimizer(
      model->parameters(), torch::optim::AdamWOptions(options.learning_rate)
                               .betas({0.9, 0.99})
                               .weight_decay(1e-6));
  torch::Generator generator =
      at::make_generator<at::CPUGeneratorImpl>(context.config.run.seed + 29);
  resume = resume && std::filesystem::exists(path);
  if (resume) {
    ResumePrior(path, model, optimizer, state);
    if (state->generator_state.defined())
      generator.set_state(state->generator_state);
  }
  StageLog log(context.RunFile("prior_log.csv"),
               "step,seconds,learning_rate,cross_entropy,accuracy,"
               "validation_cross_entropy",
               resume, state->step);
  // The last context of codes of every long sequence is held out: how far
  // the prior generalizes beyond memorizing the sequences it reads.
  std::vector<int64_t> conditions;  // view tokens, for a conditioned prior
  if (model->num_views() > 0) {
    for (int view : views) conditions.push_back(model->view_token(view));
  }
  const TokenSplit split = SplitTokensForValidation(
      token_sequences, options.context_tokens, conditions);
  TokenBatch batch;
  torch::Tensor logits, loss;
  model->train();
  // One step: a batch of (corrupted) token windows, next-token
  // cross-entropy, AdamW with the gradient norm clipped at 1.
  auto step = [&] {
    batch = SampleTokenBatch(split.training, model->num_codes(),
                             options.context_tokens, options.batch_size,
                             options.keep_probability, generator, conditions);
    logits = model->forward(batch.inputs);
    loss = NextTokenLoss(logits, batch.targets);
    optimizer.zero_grad();
    loss.backward();
    torch::nn::utils::clip_grad_norm_(model->parameters(), 1.0);
    optimizer.step();
  };
  auto report = [&](GenProgress* p) {
    torch::NoGradGuard no_grad;
    const torch::Tensor counted = batch.targets != kIgnoreTarget;
    p->loss = loss.item<double>();
    p->accuracy = logits.argmax(2)
                      .eq(batch.targets)
                      .logical_and(counted)
                      .sum()
                      .item<double>() /
                  std::max<double>(1.0, counted.sum().item<double>());
    if (split.validation.inputs.defined()) {
      model->eval();  // no dropout
      p->validation_loss =
          NextTokenLoss(model->forward(split.validation.inputs),
                        split.validation.targets)
              .item<double>();
      model->train();
    }
    char row[256];
    std::snprintf(row, sizeof(row), "%lld,%.2f,%.3g,%.6g,%.4f,%.6g",
                  static_cast<long long>(p->step), p->seconds, p->learning_rate,
                  p->loss, p->accuracy, p->validation_loss);
    return std::string(row);
  };
  auto save = [&] {
    state->generator_state = generator.get_state();
    SavePrior(path, context.config, model, &optimizer, *state);
  };
  return RunStage(context, GenStage::kPrior, options.steps,
                  options.learning_rate, optimizer, log, state, step, report,
                  save);
}

}  // namespace

GenTrainSummary TrainGenerator(
    const GenConfig& config, const GenDataset& dataset, bool resume,
    const std::atomic<bool>* stop,
    const std::function<void(const GenProgress&)>& on_progress) {
  if (dataset.sequences.empty())
    throw InputError(config.source_path, "the dataset has no sequences");
  if (config.prior_views() > 0 && dataset.num_views != config.prior_views())
    throw ConfigError("gen train: the dataset is seen from " +
                      std::to_string(dataset.num_views) +
                      " views but the config's data names " +
                      std::to_string(config.prior_views()) +
                      " (prior.condition_on_view needs them to agree)");
  for (const GenSequence& sequence : dataset.sequences) {
    if (config.prior.condition_on_motion &&
        sequence.motion >= config.prior_motions())
      throw ConfigError("gen train: sequence " + sequence.name +
                        " shows motion " + std::to_string(sequence.motion) +
                        " but the config's data names " +
                        std::to_string(config.prior_motions()) +
                        " (prior.condition_on_motion needs them to agree)");
  }
  torch::set_num_threads(config.run.torch_threads);
  std::filesystem::create_directories(config.run.run_dir);
  const StageContext context{config,
                             dataset,
                             stop,
                             on_progress,
                             torch::tensor(dataset.mean),
                             torch::tensor(dataset.std)};
  GenTrainSummary summary;
  summary.tokenizer_path = context.RunFile(kTokenizerFile);
  summary.prior_path = context.RunFile(kPriorFile);

  // 1. The tokenizer, on windows of X^can.
  torch::manual_seed(config.run.seed);
  VqVae tokenizer(dataset.frame_size, config.tokenizer);
  GenStageState tokenizer_state;
  summary.tokenizer_loss =
      TrainTokenizer(context, resume, tokenizer, &tokenizer_state);
  summary.tokenizer_steps = tokenizer_state.step;
  if (context.stop_requested()) {
    summary.interrupted = true;
    return summary;
  }
  // 2. Every sequence as codes, and the condition each is read under.
  std::vector<int> kept;
  const std::vector<std::vector<int64_t>> token_sequences =
      TokenizeDataset(tokenizer, dataset, context.mean, context.std, &kept);
  std::vector<int> views;  // condition indices (prior_conditions())
  for (int index : kept) {
    const GenSequence& sequence = dataset.sequences[index];
    views.push_back(config.PriorCondition(sequence.view, sequence.motion));
  }
  // 3. The prior, on the codes.
  torch::manual_seed(config.run.seed + 1);
  Gpt prior(config.tokenizer.num_codes, config.prior,
            config.prior_conditions());
  GenStageState prior_state;
  summary.prior_loss =
      TrainPrior(context, resume, token_sequences, views, prior, &prior_state);
  summary.prior_steps = prior_state.step;
  summary.interrupted = context.stop_requested();
  return summary;
}

}  // namespace m2d
