#include "gen/gen_checkpoint.h"

#include "common/error.h"
#include "rl/archive_file.h"

namespace m2d {
namespace {

constexpr char kTokenizerFormat[] = "mimic2d.gen.tokenizer.v1";
constexpr char kPriorFormat[] = "mimic2d.gen.prior.v1";

void WriteCommon(torch::serialize::OutputArchive& archive,
                 const GenConfig& config, torch::nn::Module& model,
                 torch::optim::Optimizer* optimizer,
                 const GenStageState& state) {
  archive.write("config_yaml", c10::IValue(GenConfigToYaml(config)));
  torch::serialize::OutputArchive model_archive;
  model.save(model_archive);
  archive.write("model", model_archive);
  if (optimizer != nullptr) {
    torch::serialize::OutputArchive optimizer_archive;
    optimizer->save(optimizer_archive);
    archive.write("optimizer", optimizer_archive);
  }
  archive.write("step", torch::full({1}, state.step, torch::kLong));
  archive.write("seconds", torch::full({1}, state.seconds, torch::kDouble));
  if (state.generator_state.defined())
    archive.write("generator_state", state.generator_state);
}

GenConfig ReadEmbeddedConfig(const std::string& path,
                             torch::serialize::InputArchive& archive) {
  c10::IValue text;
  NamingArchiveErrors(path, "no readable embedded config", [&] {
    archive.read("config_yaml", text);
    if (!text.isString()) throw InputError(path, "embedded config is not text");
  });
  return LoadGenConfigText(text.toStringRef(), path + " (embedded config)");
}

void ReadModel(const std::string& path, torch::serialize::InputArchive& archive,
               torch::nn::Module& model) {
  NamingArchiveErrors(path, "weights do not fit the model its config builds",
                      [&] {
                        torch::serialize::InputArchive model_archive;
                        archive.read("model", model_archive);
                        model.load(model_archive);
                      });
}

void ReadTraining(const std::string& path,
                  torch::serialize::InputArchive& archive,
                  torch::optim::Optimizer& optimizer, GenStageState* state) {
  NamingArchiveErrors(path, "unreadable optimizer or step", [&] {
    torch::serialize::InputArchive optimizer_archive;
    if (archive.try_read("optimizer", optimizer_archive))
      optimizer.load(optimizer_archive);
    torch::Tensor step, seconds, generator_state;
    archive.read("step", step);
    archive.read("seconds", seconds);
    state->step = step.item<int64_t>();
    state->seconds = seconds.item<double>();
    if (archive.try_read("generator_state", generator_state))
      state->generator_state = generator_state;
  });
  if (state->step < 0) throw InputError(path, "negative step count");
}

// Frame size of a tokenizer config's data (COCO-17 X^can).
int TokenizerFrameSize() { return CanonicalFrameSize(Coco17Layout()); }

}  // namespace

void SaveTokenizer(const std::string& path, const GenConfig& config,
                   VqVae& model, const torch::Tensor& mean,
                   const torch::Tensor& std, torch::optim::Optimizer* optimizer,
                   const GenStageState& state) {
  torch::serialize::OutputArchive archive;
  WriteCommon(archive, config, *model, optimizer, state);
  archive.write("mean", mean);
  archive.write("std", std);
  WriteArchiveFile(path, kTokenizerFormat, archive);
}

void SavePrior(const std::string& path, const GenConfig& config, Gpt& model,
               torch::optim::Optimizer* optimizer, const GenStageState& state) {
  torch::serialize::OutputArchive archive;
  WriteCommon(archive, config, *model, optimizer, state);
  WriteArchiveFile(path, kPriorFormat, archive);
}

LoadedTokenizer LoadTokenizer(const std::string& path) {
  torch::serialize::InputArchive archive =
      ReadArchiveFile(path, kTokenizerFormat);
  LoadedTokenizer loaded;
  loaded.config = ReadEmbeddedConfig(path, archive);
  loaded.model = VqVae(TokenizerFrameSize(), loaded.config.tokenizer);
  ReadModel(path, archive, *loaded.model);
  NamingArchiveErrors(path, "no normalization statistics", [&] {
    archive.read("mean", loaded.mean);
    archive.read("std", loaded.std);
  });
  if (loaded.mean.numel() != TokenizerFrameSize() ||
      loaded.std.numel() != TokenizerFrameSize() ||
      !(loaded.std > 0).all().item<bool>()) {
    throw InputError(path, "malformed normalization statistics");
  }
  loaded.model->eval();
  return loaded;
}

LoadedPrior LoadPrior(const std::string& path) {
  torch::serialize::InputArchive archive = ReadArchiveFile(path, kPriorFormat);
  LoadedPrior loaded;
  loaded.config = ReadEmbeddedConfig(path, archive);
  loaded.model = Gpt(loaded.config.tokenizer.num_codes, loaded.config.prior,
                     loaded.config.prior_conditions());
  ReadModel(path, archive, *loaded.model);
  loaded.model->eval();
  return loaded;
}

void ResumeTokenizer(const std::string& path, VqVae& model,
                     torch::optim::Optimizer& optimizer, GenStageState* state) {
  torch::serialize::InputArchive archive =
      ReadArchiveFile(path, kTokenizerFormat);
  ReadModel(path, archive, *model);
  ReadTraining(path, archive, optimizer, state);
}

void ResumePrior(const std::string& path, Gpt& model,
                 torch::optim::Optimizer& optimizer, GenStageState* state) {
  torch::serialize::InputArchive archive = ReadArchiveFile(path, kPriorFormat);
  ReadModel(path, archive, *model);
  ReadTraining(path, archive, optimizer, state);
}

}  // namespace m2d
