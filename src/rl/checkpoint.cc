#include "rl/checkpoint.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>
#include <utility>

#include "common/error.h"
#include "common/file_io.h"
#include "common/hash.h"
#include "rl/archive_file.h"

namespace m2d {
namespace {

constexpr char kCheckpointFormat[] = "mimic2d.checkpoint.v1";

// A SimState as one row of doubles, in a fixed field order; sizes come from
// a template state of the same model.
std::vector<std::vector<double> SimState::*> StateFields() {
  return {
      &SimState::qpos,           &SimState::qvel,      &SimState::act,
      &SimState::qacc_warmstart, &SimState::ctrl,      &SimState::qfrc_applied,
      &SimState::xfrc_applied,   &SimState::mocap_pos, &SimState::mocap_quat};
}

int64_t FlatStateSize(const SimState& state_template) {
  int64_t size = 1;  // time
  for (auto field : StateFields())
    size += static_cast<int64_t>((state_template.*field).size());
  return size;
}

void FlattenState(const SimState& state, double* out) {
  *out++ = state.time_s;
  for (auto field : StateFields()) {
    const std::vector<double>& values = state.*field;
    std::copy(values.begin(), values.end(), out);
    out += values.size();
  }
}

void UnflattenState(const double* in, const SimState& state_template,
                    SimState* state) {
  state->time_s = *in++;
  for (auto field : StateFields()) {
    size_t count = (state_template.*field).size();
    (state->*field).assign(in, in + count);
    in += count;
  }
}

}  // namespace

void SaveCheckpoint(const std::string& path, const TrainConfig& config,
                    ActorCritic& model, torch::optim::Optimizer& optimizer,
                    const CheckpointCounters& counters,
                    const InitialStates* initial_states,
                    const SimState& state_template) {
  torch::serialize::OutputArchive archive;
  archive.write("config_yaml", c10::IValue(TrainConfigToYaml(config)));
  const ObservationLayout& layout = model->layout();
  archive.write("layout",
                torch::tensor({static_cast<int64_t>(layout.num_bodies),
                               static_cast<int64_t>(layout.num_objects),
                               static_cast<int64_t>(layout.num_points),
                               static_cast<int64_t>(layout.num_future_frames),
                               static_cast<int64_t>(model->action_size()),
                               static_cast<int64_t>(layout.critic_only_size)}));
  archive.write("iteration",
                torch::tensor(static_cast<int64_t>(counters.iteration)));
  archive.write("samples", torch::tensor(counters.samples));
  archive.write("wall_time_s",
                torch::tensor(counters.wall_time_s, torch::kDouble));
  torch::serialize::OutputArchive model_archive;
  model->save(model_archive);
  archive.write("model", model_archive);
  torch::serialize::OutputArchive optimizer_archive;
  optimizer.save(optimizer_archive);
  archive.write("optimizer", optimizer_archive);
  archive.write(
      "learning_rate",
      torch::tensor(optimizer.param_groups().front().options().get_lr(),
                    torch::kDouble));

  if (initial_states != nullptr) {
    const int64_t width = FlatStateSize(state_template);
    archive.write(
        "asi_buffers",
        torch::tensor(static_cast<int64_t>(initial_states->num_buffers())));
    const uint64_t fingerprint = initial_states->reference_fingerprint();
    int64_t fingerprint_bits = 0;
    std::memcpy(&fingerprint_bits, &fingerprint, sizeof(fingerprint_bits));
    archive.write("asi_reference", torch::tensor(fingerprint_bits));
    for (int b = 0; b < initial_states->num_buffers(); ++b) {
      const StateBuffer& buffer = initial_states->buffer(b);
      int64_t entries = 0;
      for (int f = 0; f < buffer.num_frames(); ++f) entries += buffer.size(f);
      torch::Tensor states = torch::zeros({entries, width}, torch::kDouble);
      torch::Tensor scores = torch::zeros({entries}, torch::kDouble);
      torch::Tensor frames = torch::zeros({entries}, torch::kLong);
      int64_t row = 0;
      for (int f = 0; f < buffer.num_frames(); ++f) {
        for (int i = 0; i < buffer.size(f); ++i, ++row) {
          FlattenState(buffer.entry(f, i).state,
                       states[row].data_ptr<double>());
          scores[row] = buffer.entry(f, i).score;
          frames[row] = f;
        }
      }
      std::string prefix = "asi_" + std::to_string(b) + "_";
      archive.write(prefix + "states", states);
      archive.write(prefix + "scores", scores);
      archive.write(prefix + "frames", frames);
    }
  }

  WriteArchiveFile(path, kCheckpointFormat, archive);
}

namespace {

torch::serialize::InputArchive OpenArchive(const std::string& path) {
  return ReadArchiveFile(path, kCheckpointFormat);
}

// The config embedded in `archive`, read from the file `path`.
TrainConfig EmbeddedConfig(const std::string& path,
                           torch::serialize::InputArchive& archive) {
  c10::IValue text;
  NamingArchiveErrors(path, "no readable embedded config", [&] {
    archive.read("config_yaml", text);
    if (!text.isString()) throw InputError(path, "embedded config is not text");
  });
  return LoadTrainConfigText(text.toStringRef(), path + " (embedded config)");
}

// The layout and action size saved in `archive`, read from `path`.
ObservationLayout SavedLayout(const std::string& path,
                              torch::serialize::InputArchive& archive,
                              int* action_size) {
  return NamingArchiveErrors(path, "malformed layout", [&] {
    torch::Tensor values;
    archive.read("layout", values);
    values = values.to(torch::kInt64).flatten();
    // 6 counts; checkpoints from before the critic-only block hold 5.
    if (values.numel() != 5 && values.numel() != 6)
      throw InputError(path, "layout must hold 5 or 6 counts");
    // Bounds far above any character, so that a damaged count is named
    // here rather than sizing networks beyond memory.
    auto count = [&](int index, const char* name, int64_t low, int64_t high) {
      const int64_t value = values[index].item<int64_t>();
      if (value < low || value > high) {
        throw InputError(path, std::string("layout ") + name + " " +
                                   std::to_string(value) + " outside [" +
                                   std::to_string(low) + ", " +
                                   std::to_string(high) + "]");
      }
      return static_cast<int>(value);
    };
    ObservationLayout layout;
    layout.num_bodies = count(0, "num_bodies", 1, 1000);
    layout.num_objects = count(1, "num_objects", 0, 100);
    layout.num_points = count(2, "num_points", 1, 1000);
    layout.num_future_frames = count(3, "num_future_frames", 0, 1000);
    *action_size = count(4, "action_size", 1, 1000);
    if (values.numel() == 6)
      layout.critic_only_size = count(5, "critic_only_size", 0, 100000);
    return layout;
  });
}

}  // namespace

TrainConfig ReadCheckpointConfig(const std::string& path) {
  torch::serialize::InputArchive archive = OpenArchive(path);
  return EmbeddedConfig(path, archive);
}

ObservationLayout ReadCheckpointLayout(const std::string& path,
                                       int* action_size) {
  torch::serialize::InputArchive archive = OpenArchive(path);
  return SavedLayout(path, archive, action_size);
}

namespace {

// Reads the tensor `name` (from character `begin` on) of a module archive:
// "actor.0.weight" is tensor "weight" of archive "0" of archive "actor".
bool ReadNestedTensor(torch::serialize::InputArchive& archive,
                      const std::string& name, size_t begin,
                      torch::Tensor* tensor) {
  const size_t dot = name.find('.', begin);
  if (dot == std::string::npos)
    return archive.try_read(name.substr(begin), *tensor);
  torch::serialize::InputArchive child;
  if (!archive.try_read(name.substr(begin, dot - begin), child)) return false;
  return ReadNestedTensor(child, name, dot + 1, tensor);
}

// The network in `archive` must be the one `model` is: the observation
// layout, the action count and every parameter's shape (hidden sizes).
// A mismatch is a named error before anything is loaded; LibTorch would
// otherwise replace the tensors and fail later with a backtrace.
void CheckSameNetwork(const std::string& path,
                      torch::serialize::InputArchive& archive,
                      const ActorCritic& model) {
  torch::Tensor values;
  archive.read("layout", values);
  const ObservationLayout& layout = model->layout();
  const std::pair<const char*, int64_t> fields[] = {
      {"character bodies", layout.num_bodies},
      {"objects", layout.num_objects},
      {"2D points per frame", layout.num_points},
      {"future frames (env.num_future_frames)", layout.num_future_frames},
      {"actions", model->action_size()},
      {"critic-only inputs (env.critic_observes_3d)", layout.critic_only_size}};
  values = values.to(torch::kInt64).flatten();
  for (int i = 0; i < 6; ++i) {
    const int64_t saved = i < values.numel() ? values[i].item<int64_t>() : 0;
    if (saved != fields[i].second) {
      throw InputError(path, std::string("was trained with ") +
                                 std::to_string(saved) + " " + fields[i].first +
                                 "; this config has " +
                                 std::to_string(fields[i].second) +
                                 ": a structural setting changed (start a new "
                                 "run_dir, or restore the setting)");
    }
  }
  // Each parameter, by its dotted name in the nested module archives that
  // Module::save writes.
  torch::serialize::InputArchive model_archive;
  archive.read("model", model_archive);
  for (const auto& parameter : model->named_parameters()) {
    torch::Tensor saved;
    if (!ReadNestedTensor(model_archive, parameter.key(), 0, &saved) ||
        saved.sizes() != parameter.value().sizes()) {
      throw InputError(path, "its network differs from this config's (" +
                                 parameter.key() +
                                 ": model.*_hidden or encoder_features "
                                 "changed); start a new run_dir, or restore "
                                 "the model settings");
    }
  }
}

// The reference fingerprint the buffers in `archive` were filled for
// (stored as an int64 tensor's bits); nullopt in older checkpoints.
std::optional<uint64_t> SavedReferenceFingerprint(
    torch::serialize::InputArchive& archive) {
  torch::Tensor saved;
  if (!archive.try_read("asi_reference", saved)) return std::nullopt;
  const int64_t bits = saved.item<int64_t>();
  uint64_t fingerprint = 0;
  std::memcpy(&fingerprint, &bits, sizeof(bits));
  return fingerprint;
}

// The training counters saved in `archive`. Throws c10::Error when absent.
CheckpointCounters ReadCounters(torch::serialize::InputArchive& archive) {
  CheckpointCounters counters;
  // A fresh tensor per read: reading into a defined tensor keeps its
  // dtype and reinterprets the bytes (a double read as int64).
  torch::Tensor iteration, samples, wall_time_s, learning_rate;
  archive.read("iteration", iteration);
  counters.iteration = static_cast<int>(iteration.item<int64_t>());
  archive.read("samples", samples);
  counters.samples = samples.item<int64_t>();
  archive.read("wall_time_s", wall_time_s);
  counters.wall_time_s = wall_time_s.item<double>();
  if (archive.try_read("learning_rate", learning_rate))
    counters.learning_rate = learning_rate.item<double>();
  return counters;
}

// How many ASI buffers `archive` holds (0 for a slim checkpoint).
int64_t SavedBufferCount(torch::serialize::InputArchive& archive) {
  torch::Tensor saved_buffers;
  if (archive.try_read("asi_buffers", saved_buffers)) {
    return saved_buffers.item<int64_t>();
  }
  int64_t num_saved = 0;  // older checkpoints: count the buffers present
  torch::Tensor probe;
  while (
      archive.try_read("asi_" + std::to_string(num_saved) + "_states", probe))
    ++num_saved;
  return num_saved;
}

// Restores the ASI buffers saved in `archive` into `initial_states` (see
// LoadCheckpoint). Throws c10::Error on malformed tensors.
void RestoreStateBuffers(const std::string& path,
                         torch::serialize::InputArchive& archive,
                         InitialStates* initial_states,
                         const SimState& state_template) {
  const int64_t width = FlatStateSize(state_template);
  // The buffers must be this task's: one per bundle (truth, default
  // starts) or one per view (estimate).
  const int64_t num_saved = SavedBufferCount(archive);
  if (num_saved > 0 && num_saved != initial_states->num_buffers()) {
    throw InputError(path,
                     "holds " + std::to_string(num_saved) +
                         " initial-state buffers but this task has " +
                         std::to_string(initial_states->num_buffers()) +
                         " (initial_states: estimate keeps one per view, truth "
                         "and default one per bundle): the config's bundles or "
                         "initial_states differ from the checkpoint's");
  }
  // Buffers filled for another reference (other bundles of the same
  // length) would start episodes from the wrong motion: keep this
  // task's fresh buffers instead, and say so.
  const std::optional<uint64_t> saved_fingerprint =
      SavedReferenceFingerprint(archive);
  const bool same_reference =
      !saved_fingerprint ||
      *saved_fingerprint == initial_states->reference_fingerprint();
  if (!same_reference) {
    spdlog::warn(
        "{}: its initial-state buffers were filled for other reference "
        "motion (the bundles' 2D differ); starting this task's buffers "
        "fresh",
        path);
  }
  for (int b = 0; same_reference && b < initial_states->num_buffers(); ++b) {
    std::string prefix = "asi_" + std::to_string(b) + "_";
    torch::Tensor states, scores, frames;
    if (!archive.try_read(prefix + "states", states)) continue;
    archive.read(prefix + "scores", scores);
    archive.read(prefix + "frames", frames);
    if (states.size(1) != width)
      throw InputError(path, "ASI states do not fit this model");
    StateBuffer& buffer = initial_states->buffer(b);
    StateBuffer restored(buffer.num_frames(),
                         StateBufferOptions(buffer.options()));
    // Anchors are this task's own fill, never saved: keep them.
    for (int f = 0; f < buffer.num_frames(); ++f) {
      if (const SimState* anchor = buffer.anchor(f))
        restored.SetAnchor(f, *anchor);
    }
    SimState state;
    for (int64_t row = 0; row < states.size(0); ++row) {
      int frame = static_cast<int>(frames[row].item<int64_t>());
      if (frame < 0 || frame >= buffer.num_frames())
        throw InputError(path, "ASI frame out of range");
      UnflattenState(states[row].data_ptr<double>(), state_template, &state);
      restored.Insert(frame, state, scores[row].item<double>());
    }
    buffer = std::move(restored);
  }
}

}  // namespace

CheckpointCounters LoadCheckpoint(const std::string& path, ActorCritic& model,
                                  torch::optim::Optimizer* optimizer,
                                  InitialStates* initial_states,
                                  const SimState& state_template) {
  torch::serialize::InputArchive archive = OpenArchive(path);
  CheckpointCounters counters;
  try {
    CheckSameNetwork(path, archive, model);
    counters = ReadCounters(archive);
    torch::serialize::InputArchive model_archive;
    archive.read("model", model_archive);
    model->load(model_archive);
    if (optimizer != nullptr) {
      torch::serialize::InputArchive optimizer_archive;
      archive.read("optimizer", optimizer_archive);
      optimizer->load(optimizer_archive);
      if (counters.learning_rate > 0) {
        for (torch::optim::OptimizerParamGroup& group :
             optimizer->param_groups())
          group.options().set_lr(counters.learning_rate);
      }
    }
    if (initial_states != nullptr)
      RestoreStateBuffers(path, archive, initial_states, state_template);
  } catch (const InputError&) {
    throw;
  } catch (const c10::Error& e) {
    throw InputError(path, "checkpoint does not match this config (" +
                               std::string(e.what_without_backtrace()) + ")");
  } catch (const std::exception& e) {
    throw InputError(path,
                     std::string("malformed checkpoint (") + e.what() + ")");
  }
  return counters;
}

void LoadCheckpointStateBuffers(const std::string& path,
                                InitialStates* initial_states,
                                const SimState& state_template) {
  torch::serialize::InputArchive archive = OpenArchive(path);
  NamingArchiveErrors(path, "initial-state buffers do not fit this task", [&] {
    torch::Tensor saved_buffers;
    if (!archive.try_read("asi_buffers", saved_buffers)) {
      throw InputError(path, "holds no initial-state buffers");
    }
    // Only buffers known to belong to this reference: a checkpoint from
    // before fingerprints cannot say which motion its buffers are of.
    const std::optional<uint64_t> fingerprint =
        SavedReferenceFingerprint(archive);
    if (!fingerprint) {
      throw InputError(path,
                       "its initial-state buffers carry no reference "
                       "fingerprint (an older checkpoint): cannot tell which "
                       "motion they belong to");
    }
    if (*fingerprint != initial_states->reference_fingerprint()) {
      throw InputError(path,
                       "its initial-state buffers were filled for other "
                       "reference motion than these bundles'");
    }
    RestoreStateBuffers(path, archive, initial_states, state_template);
  });
}

SlimCheckpointSummary WriteSlimCheckpoint(const std::string& in,
                                          const std::string& out) {
  // Build the networks and optimizer the checkpoint's own config describes,
  // load everything but the buffers, and save with none.
  const TrainConfig config = ReadCheckpointConfig(in);
  int action_size = 0;
  const ObservationLayout layout = ReadCheckpointLayout(in, &action_size);
  ActorCritic model(layout, config.model, action_size);
  torch::optim::Adam optimizer(
      model->parameters(), torch::optim::AdamOptions(config.ppo.learning_rate));
  const CheckpointCounters counters = LoadCheckpoint(
      in, model, &optimizer, /*initial_states=*/nullptr, SimState());
  SlimCheckpointSummary summary;
  summary.bytes_before = static_cast<int64_t>(std::filesystem::file_size(in));
  summary.samples = counters.samples;
  SaveCheckpoint(out, config, model, optimizer, counters,
                 /*initial_states=*/nullptr, SimState());
  summary.bytes_after = static_cast<int64_t>(std::filesystem::file_size(out));
  return summary;
}

AveragedCheckpointSummary AverageCheckpoints(
    const std::vector<std::string>& inputs, const std::string& out) {
  if (inputs.size() < 2) {
    throw ConfigError("checkpoint average: needs 2 or more checkpoints, got " +
                      std::to_string(inputs.size()));
  }
  // The newest input (most samples) gives the networks' shape, optimizer,
  // counters and config: a shell glob lists ckpt_<samples>.pt by text, so
  // 9.9M comes after 10.1M. Every other input loads into a copy of its
  // networks (LoadCheckpoint names a file whose networks or layout differ)
  // and is summed into the running total.
  std::vector<int64_t> input_samples;
  size_t newest = 0;
  CheckpointInfo newest_info;
  for (size_t i = 0; i < inputs.size(); ++i) {
    CheckpointInfo info = ReadCheckpointInfo(inputs[i]);
    input_samples.push_back(info.counters.samples);
    if (i == 0 || info.counters.samples > input_samples[newest]) {
      newest = i;
      newest_info = std::move(info);
    }
  }
  const std::string& base = inputs[newest];
  const TrainConfig& config = newest_info.config;
  const ObservationLayout& layout = newest_info.layout;
  const int action_size = newest_info.action_size;
  ActorCritic mean_model(layout, config.model, action_size);
  torch::optim::Adam optimizer(
      mean_model->parameters(),
      torch::optim::AdamOptions(config.ppo.learning_rate));
  const CheckpointCounters counters = LoadCheckpoint(
      base, mean_model, &optimizer, /*initial_states=*/nullptr, SimState());
  AveragedCheckpointSummary summary;
  summary.num_averaged = static_cast<int>(inputs.size());
  summary.first_samples =
      *std::min_element(input_samples.begin(), input_samples.end());
  summary.last_samples = counters.samples;
  torch::NoGradGuard no_grad;
  auto mean_parameters = mean_model->named_parameters();
  auto mean_buffers = mean_model->named_buffers();
  for (size_t i = 0; i < inputs.size(); ++i) {
    if (i == newest) continue;
    ActorCritic model(layout, config.model, action_size);
    LoadCheckpoint(inputs[i], model, /*optimizer=*/nullptr,
                   /*initial_states=*/nullptr, SimState());
    // Parameters, then buffers (the normalizers' mean, variance and count),
    // matched by name.
    for (auto& named : model->named_parameters())
      mean_parameters[named.key()].add_(named.value());
    for (auto& named : model->named_buffers())
      mean_buffers[named.key()].add_(named.value());
  }
  const double scale = 1.0 / static_cast<double>(inputs.size());
  for (auto& named : mean_parameters) named.value().mul_(scale);
  for (auto& named : mean_buffers) named.value().mul_(scale);
  SaveCheckpoint(out, config, mean_model, optimizer, counters,
                 /*initial_states=*/nullptr, SimState());
  return summary;
}

CheckpointInfo ReadCheckpointInfo(const std::string& path) {
  // One read of the file (a checkpoint with buffers is tens of MB).
  CheckpointInfo info;
  torch::serialize::InputArchive archive = OpenArchive(path);
  info.config = EmbeddedConfig(path, archive);
  info.layout = SavedLayout(path, archive, &info.action_size);
  info.bytes = static_cast<int64_t>(std::filesystem::file_size(path));
  NamingArchiveErrors(path, "malformed checkpoint", [&] {
    info.counters = ReadCounters(archive);
    info.num_state_buffers = static_cast<int>(SavedBufferCount(archive));
    for (int b = 0; b < info.num_state_buffers; ++b) {
      torch::Tensor frames;
      if (archive.try_read("asi_" + std::to_string(b) + "_frames", frames))
        info.num_buffered_states += frames.numel();
    }
  });
  return info;
}

}  // namespace m2d
