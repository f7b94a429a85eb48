#include "rl/checkpoint.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "env/env_fixture.h"
#include "env/task.h"
#include "small_networks.h"
#include "test_paths.h"

namespace m2d {
namespace {

using testing::SmallLayout;
using testing::SmallModel;

namespace fs = std::filesystem;

constexpr int kActions = 4;

// A model whose weights, normalizer buffers and Adam moments have all moved
// from their initial values, as in a real run.
struct TrainedModel {
  ActorCritic model{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer;
};

torch::Tensor Loss(ActorCritic& model, const torch::Tensor& raw) {
  torch::Tensor obs = model->Normalize(raw);
  return model->ActionMean(obs).pow(2).mean() +
         (model->Value(obs) - 1.0).pow(2).mean();
}

TrainedModel MakeTrainedModel(const ObservationLayout& layout, int actions,
                              uint64_t seed) {
  torch::manual_seed(seed);
  TrainedModel trained;
  trained.model = ActorCritic(layout, SmallModel(), actions);
  trained.optimizer = std::make_unique<torch::optim::Adam>(
      trained.model->parameters(), torch::optim::AdamOptions(1e-3));
  for (int step = 0; step < 3; ++step) {
    torch::Tensor raw = torch::randn({16, layout.size()}) * 2.0 + 0.5;
    trained.model->UpdateNormalizer(raw);
    trained.optimizer->zero_grad();
    Loss(trained.model, raw).backward();
    trained.optimizer->step();
  }
  return trained;
}

// A model and optimizer as a resuming trainer builds them: same config,
// different random initialization, no optimizer state.
TrainedModel MakeFreshModel(const ObservationLayout& layout, int actions,
                            uint64_t seed) {
  torch::manual_seed(seed);
  TrainedModel fresh;
  fresh.model = ActorCritic(layout, SmallModel(), actions);
  fresh.optimizer = std::make_unique<torch::optim::Adam>(
      fresh.model->parameters(), torch::optim::AdamOptions(1e-3));
  return fresh;
}

bool SameTensors(const torch::OrderedDict<std::string, torch::Tensor>& a,
                 const torch::OrderedDict<std::string, torch::Tensor>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].key() != b[i].key() || !torch::equal(a[i].value(), b[i].value()))
      return false;
  }
  return true;
}

// One Adam step of both on the same batch; true when their weights then
// agree, i.e. weights, normalizer and Adam's moments were all the same.
bool TheNextUpdateIsTheSame(const ObservationLayout& layout,
                            TrainedModel& saved, TrainedModel& loaded) {
  torch::manual_seed(3);
  torch::Tensor raw = torch::randn({16, layout.size()});
  for (TrainedModel* model : {&saved, &loaded}) {
    model->optimizer->zero_grad();
    Loss(model->model, raw).backward();
    model->optimizer->step();
  }
  return SameTensors(saved.model->named_parameters(),
                     loaded.model->named_parameters());
}

// LibTorch keys optimizer state by the parameter's TensorImpl address.
const torch::optim::AdamParamState* AdamState(
    const torch::optim::Adam& optimizer, const torch::Tensor& parameter) {
  auto it = optimizer.state().find(
      c10::guts::to_string(parameter.unsafeGetTensorImpl()));
  if (it == optimizer.state().end()) return nullptr;
  return static_cast<const torch::optim::AdamParamState*>(it->second.get());
}

TEST(Checkpoint, CountersModelAndOptimizerRoundTrip) {
  const std::string dir = testing::TempDir("checkpoint_round_trip");
  const std::string path = dir + "/checkpoint.pt";
  ObservationLayout layout = SmallLayout();
  layout.critic_only_size = 7;  // the asymmetric critic's inputs
  TrainedModel saved = MakeTrainedModel(layout, kActions, 1);
  TrainConfig config;
  config.data.bundles = {"walk.json"};  // read back, so it must validate
  config.ppo.num_envs = 24;  // 24 x 32 steps: room for the 512 minibatch
  config.model = SmallModel();
  CheckpointCounters counters;
  counters.iteration = 37;
  counters.samples = 123'456'789'012;  // past 2^32
  counters.wall_time_s = 2775.83;      // not an integer
  // An adapted rate (target_kl): fresh optimizers start at 1e-3.
  for (auto& group : saved.optimizer->param_groups())
    group.options().set_lr(1.75e-5);
  SaveCheckpoint(path, config, saved.model, *saved.optimizer, counters, nullptr,
                 SimState());

  TrainedModel loaded = MakeFreshModel(layout, kActions, 2);
  ASSERT_FALSE(SameTensors(saved.model->named_parameters(),
                           loaded.model->named_parameters()));
  ASSERT_FALSE(
      SameTensors(saved.model->named_buffers(), loaded.model->named_buffers()));
  CheckpointCounters read = LoadCheckpoint(
      path, loaded.model, loaded.optimizer.get(), nullptr, SimState());
  EXPECT_EQ(read.iteration, 37);
  EXPECT_EQ(read.samples, 123'456'789'012);
  EXPECT_EQ(read.wall_time_s, 2775.83);  // exactly: stored as a double
  // LibTorch's Optimizer::load alone would leave the fresh 1e-3.
  EXPECT_EQ(read.learning_rate, 1.75e-5);
  for (const auto& group : loaded.optimizer->param_groups())
    EXPECT_EQ(group.options().get_lr(), 1.75e-5);

  // Weights and the observation normalizer's running statistics.
  EXPECT_TRUE(SameTensors(saved.model->named_parameters(),
                          loaded.model->named_parameters()));
  EXPECT_TRUE(
      SameTensors(saved.model->named_buffers(), loaded.model->named_buffers()));

  // Adam's per-parameter step count and moments. The fixed log_std takes no
  // gradient, so Adam keeps no state for it.
  const std::vector<torch::Tensor> saved_parameters = saved.model->parameters();
  const std::vector<torch::Tensor> loaded_parameters =
      loaded.model->parameters();
  ASSERT_EQ(saved_parameters.size(), loaded_parameters.size());
  int with_state = 0;
  for (size_t i = 0; i < saved_parameters.size(); ++i) {
    SCOPED_TRACE(i);
    const auto* before = AdamState(*saved.optimizer, saved_parameters[i]);
    const auto* after = AdamState(*loaded.optimizer, loaded_parameters[i]);
    ASSERT_EQ(before == nullptr, after == nullptr);
    if (before == nullptr) continue;
    ++with_state;
    EXPECT_EQ(before->step(), 3);
    EXPECT_EQ(after->step(), 3);
    EXPECT_TRUE(torch::equal(before->exp_avg(), after->exp_avg()));
    EXPECT_TRUE(torch::equal(before->exp_avg_sq(), after->exp_avg_sq()));
  }
  EXPECT_EQ(with_state, static_cast<int>(saved_parameters.size()) - 1);

  // So the next update is the one the saved run would have made.
  EXPECT_TRUE(TheNextUpdateIsTheSame(layout, saved, loaded));

  // The embedded config and layout rebuild the networks.
  EXPECT_EQ(ReadCheckpointConfig(path).ppo.num_envs, 24);
  int action_size = 0;
  ObservationLayout read_layout = ReadCheckpointLayout(path, &action_size);
  EXPECT_EQ(action_size, kActions);
  EXPECT_EQ(read_layout.size(), layout.size());
  EXPECT_EQ(read_layout.num_bodies, layout.num_bodies);
  EXPECT_EQ(read_layout.num_future_frames, layout.num_future_frames);
  EXPECT_EQ(read_layout.critic_only_size, 7);
  fs::remove_all(dir);
}

// Expects `load` to throw an InputError naming `path`.
template <typename Load>
void ExpectInputErrorNaming(const std::string& path, Load load) {
  try {
    load();
    ADD_FAILURE() << "expected InputError for " << path;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path);
  }
}

TEST(Checkpoint, TruncatedOrForeignFilesAreInputErrorsNamingTheFile) {
  const std::string dir = testing::TempDir("checkpoint_corrupt");
  const std::string path = dir + "/checkpoint.pt";
  TrainedModel saved = MakeTrainedModel(SmallLayout(), kActions, 1);
  SaveCheckpoint(path, TrainConfig(), saved.model, *saved.optimizer,
                 CheckpointCounters(), nullptr, SimState());
  TrainedModel loaded = MakeFreshModel(SmallLayout(), kActions, 2);

  // A copy cut in half, as a kill during a non-atomic copy would leave it.
  const std::string truncated = dir + "/truncated.pt";
  fs::copy_file(path, truncated);
  fs::resize_file(truncated, fs::file_size(path) / 2);
  ExpectInputErrorNaming(truncated, [&] {
    LoadCheckpoint(truncated, loaded.model, loaded.optimizer.get(), nullptr,
                   SimState());
  });
  ExpectInputErrorNaming(truncated, [&] { ReadCheckpointConfig(truncated); });

  // A whole LibTorch archive without our trailer (another program's, or
  // one whose end was lost): LibTorch's reader never sees it.
  const std::string untrailed = dir + "/untrailed.pt";
  fs::copy_file(path, untrailed);
  fs::resize_file(untrailed, fs::file_size(path) - 16);
  std::string untrailed_message;
  try {
    ReadCheckpointConfig(untrailed);
  } catch (const InputError& e) {
    untrailed_message = e.what();
  }
  EXPECT_NE(untrailed_message.find("checksum trailer"), std::string::npos)
      << untrailed_message;

  const std::string text = dir + "/notes.pt";
  std::ofstream(text) << "not a checkpoint\n";
  ExpectInputErrorNaming(text, [&] {
    LoadCheckpoint(text, loaded.model, nullptr, nullptr, SimState());
  });

  // One flipped bit inside a weight: the file still parses, the checksum
  // does not match.
  const std::string flipped = dir + "/flipped.pt";
  fs::copy_file(path, flipped);
  {
    std::fstream file(flipped, std::ios::in | std::ios::out | std::ios::binary);
    const std::streamoff middle =
        static_cast<std::streamoff>(fs::file_size(flipped) / 2);
    file.seekg(middle);
    char byte = 0;
    file.read(&byte, 1);
    byte ^= 0x10;
    file.seekp(middle);
    file.write(&byte, 1);
  }
  std::string message;
  try {
    LoadCheckpoint(flipped, loaded.model, loaded.optimizer.get(), nullptr,
                   SimState());
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(flipped), std::string::npos) << message;
  EXPECT_NE(message.find("checksum does not match"), std::string::npos)
      << message;

  const std::string missing = dir + "/missing.pt";
  ExpectInputErrorNaming(missing, [&] {
    LoadCheckpoint(missing, loaded.model, nullptr, nullptr, SimState());
  });
  fs::remove_all(dir);
}

TEST(Checkpoint, AFailedSaveLeavesThePreviousCheckpoint) {
  const std::string dir = testing::TempDir("checkpoint_atomic");
  const std::string path = dir + "/checkpoint.pt";
  TrainedModel first = MakeTrainedModel(SmallLayout(), kActions, 1);
  CheckpointCounters counters;
  counters.iteration = 5;
  counters.wall_time_s = 12.5;
  SaveCheckpoint(path, TrainConfig(), first.model, *first.optimizer, counters,
                 nullptr, SimState());
  // Only the checkpoint remains: the temporary file was renamed over it.
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

  // The save writes a temporary file next to the checkpoint first; a
  // directory in its place makes that write fail (as a full disk would).
  // (Running as root, a read-only folder would not stop the write.)
  const std::string blocked = path + ".tmp." + std::to_string(::getpid());
  fs::create_directory(blocked);
  TrainedModel second = MakeTrainedModel(SmallLayout(), kActions, 9);
  counters.iteration = 6;
  try {
    SaveCheckpoint(path, TrainConfig(), second.model, *second.optimizer,
                   counters, nullptr, SimState());
    ADD_FAILURE() << "the save into a blocked temporary path succeeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), path);
    EXPECT_NE(std::string(e.what()).find("cannot write checkpoint"),
              std::string::npos)
        << e.what();
  }
  TrainedModel loaded = MakeFreshModel(SmallLayout(), kActions, 2);
  CheckpointCounters read =
      LoadCheckpoint(path, loaded.model, nullptr, nullptr, SimState());
  EXPECT_EQ(read.iteration, 5);
  EXPECT_EQ(read.wall_time_s, 12.5);
  EXPECT_TRUE(SameTensors(first.model->named_parameters(),
                          loaded.model->named_parameters()));

  // A full disk (a file-size limit makes the write fail with EFBIG, as
  // ENOSPC would): a named error, not an abort, and the previous checkpoint
  // still loads.
  fs::remove(blocked);
  {
    struct rlimit saved_limit;
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved_limit), 0);
    void (*saved_handler)(int) = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = saved_limit;
    small.rlim_cur = 64 * 1024;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
    std::string message;
    try {
      SaveCheckpoint(path, TrainConfig(), second.model, *second.optimizer,
                     counters, nullptr, SimState());
    } catch (const InputError& e) {
      message = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &saved_limit);
    std::signal(SIGXFSZ, saved_handler);
    EXPECT_NE(message.find("cannot write checkpoint"), std::string::npos)
        << message;
    EXPECT_NE(message.find("previous checkpoint is unchanged"),
              std::string::npos)
        << message;
  }
  EXPECT_EQ(LoadCheckpoint(path, loaded.model, nullptr, nullptr, SimState())
                .iteration,
            5);
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

  // Saving into a folder that does not exist fails and creates nothing.
  const std::string nowhere = dir + "/no_such_dir/checkpoint.pt";
  EXPECT_THROW(SaveCheckpoint(nowhere, TrainConfig(), second.model,
                              *second.optimizer, counters, nullptr, SimState()),
               InputError);
  EXPECT_FALSE(fs::exists(dir + "/no_such_dir"));
  fs::remove_all(dir);
}

TEST(Checkpoint, InitialStateBuffersRoundTrip) {
  M2D_REQUIRE_SHARED(walk_path, "deepmimic/motions/humanoid3d_walk.txt");
  const std::string dir = testing::TempDir("checkpoint_asi");
  const std::string path = dir + "/checkpoint.pt";
  testing::WalkTask task = testing::MakeWalkTask(walk_path, 1.0);
  const SimState state_template =
      Simulation(task.character, task.options.simulation).Save();
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0);
  TrainedModel saved = MakeTrainedModel(env.layout(), env.action_size(), 1);

  // ASI as training leaves it: visited states with critic scores added to
  // some frames (distinct states, so a mix-up would show).
  StateBuffer& buffer = task.initial_states->buffer(0);
  const int capacity = buffer.options().capacity_per_frame;
  for (int frame : {0, 7, buffer.num_frames() - 1}) {
    for (int k = 0; k < capacity; ++k) {
      SimState state = buffer.entry(frame, 0).state;
      state.qpos[0] += 0.01 * (k + 1);
      state.qvel[2] -= 0.3 * k;
      state.time_s += 0.001 * k;
      buffer.Insert(frame, state, 1.5 + 0.25 * k + frame);
    }
  }
  SaveCheckpoint(path, TrainConfig(), saved.model, *saved.optimizer,
                 CheckpointCounters(), task.initial_states.get(),
                 state_template);

  InitialStates restored(*task.reference, task.character,
                         task.options.simulation, StateBufferOptions());
  ASSERT_NE(restored.buffer(0).size(7), buffer.size(7));
  TrainedModel loaded = MakeFreshModel(env.layout(), env.action_size(), 2);
  LoadCheckpoint(path, loaded.model, loaded.optimizer.get(), &restored,
                 state_template);

  const StateBuffer& read = restored.buffer(0);
  ASSERT_EQ(read.num_frames(), buffer.num_frames());
  for (int f = 0; f < buffer.num_frames(); ++f) {
    ASSERT_EQ(read.size(f), buffer.size(f)) << "frame " << f;
    // Anchors are the task's own fill, kept through the restore.
    ASSERT_NE(read.anchor(f), nullptr) << "frame " << f;
    EXPECT_EQ(read.anchor(f)->qpos, buffer.anchor(f)->qpos) << "frame " << f;
    for (int i = 0; i < buffer.size(f); ++i) {
      SCOPED_TRACE("frame " + std::to_string(f) + " entry " +
                   std::to_string(i));
      const ScoredState& a = buffer.entry(f, i);
      const ScoredState& b = read.entry(f, i);
      EXPECT_EQ(b.score, a.score);
      EXPECT_EQ(b.state.time_s, a.state.time_s);
      EXPECT_EQ(b.state.qpos, a.state.qpos);
      EXPECT_EQ(b.state.qvel, a.state.qvel);
      EXPECT_EQ(b.state.act, a.state.act);
      EXPECT_EQ(b.state.qacc_warmstart, a.state.qacc_warmstart);
      EXPECT_EQ(b.state.ctrl, a.state.ctrl);
      EXPECT_EQ(b.state.qfrc_applied, a.state.qfrc_applied);
      EXPECT_EQ(b.state.xfrc_applied, a.state.xfrc_applied);
      EXPECT_EQ(b.state.mocap_pos, a.state.mocap_pos);
      EXPECT_EQ(b.state.mocap_quat, a.state.mocap_quat);
    }
  }
  fs::remove_all(dir);
}

// Buffers saved for one task (truth: one per bundle) cannot be loaded into
// another (estimate: one per view): a clear error, not a silent mix-up.
TEST(Checkpoint, InitialStateBuffersOfAnotherTaskAreRejected) {
  const std::string dir = testing::TempDir("checkpoint_buffers");
  const std::string path = dir + "/checkpoint.pt";
  TrackingTaskOptions options;
  auto character = testing::LoadHumanoid(options.simulation);
  ReferenceBundle bundle = testing::MakeGlidingBundle(*character, 0.5);
  bundle.estimate = testing::EstimateFromTruth(bundle, {{0.5, {1, 0, 0}}});
  TrackingTask truth = BuildTrackingTask(character, {bundle}, options);
  options.sources = {InitialStateSource::kEstimate, CameraSource::kEstimate};
  TrackingTask estimate = BuildTrackingTask(character, {bundle}, options);
  ASSERT_EQ(truth.initial_states->num_buffers(), 1);
  ASSERT_EQ(estimate.initial_states->num_buffers(), 2);
  const SimState state_template =
      Simulation(character, options.simulation).Save();
  TrainedModel saved = MakeTrainedModel(SmallLayout(), kActions, 1);
  SaveCheckpoint(path, TrainConfig(), saved.model, *saved.optimizer,
                 CheckpointCounters(), truth.initial_states.get(),
                 state_template);

  TrainedModel loaded = MakeFreshModel(SmallLayout(), kActions, 2);
  try {
    LoadCheckpoint(path, loaded.model, loaded.optimizer.get(),
                   estimate.initial_states.get(), state_template);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("holds 1 initial-state buffers but this task has 2"),
              std::string::npos)
        << message;
  }
  // The same task loads.
  EXPECT_NO_THROW(LoadCheckpoint(path, loaded.model, loaded.optimizer.get(),
                                 truth.initial_states.get(), state_template));
  fs::remove_all(dir);
}

// `checkpoint slim`: the buffers go, everything a policy or a resumed run
// reads stays, bit for bit.
TEST(Checkpoint, ASlimCheckpointKeepsAllButTheStateBuffersAndInfoSaysSo) {
  const std::string dir = testing::TempDir("checkpoint_slim");
  const std::string path = dir + "/checkpoint.pt";
  const std::string slim_path = dir + "/slim.pt";
  TrackingTaskOptions options;
  auto character = testing::LoadHumanoid(options.simulation);
  ReferenceBundle bundle = testing::MakeGlidingBundle(*character, 0.5);
  TrackingTask task = BuildTrackingTask(character, {bundle}, options);
  const SimState state_template =
      Simulation(character, options.simulation).Save();
  StateBuffer& buffer = task.initial_states->buffer(0);
  const int fresh_size = buffer.size(3);
  for (int k = 0; k < buffer.options().capacity_per_frame; ++k) {
    SimState state = buffer.entry(3, 0).state;
    state.qpos[0] += 0.01 * (k + 1);
    buffer.Insert(3, state, 2.0 + k);
  }
  ASSERT_GT(buffer.size(3), fresh_size);
  TrainConfig config;
  config.data.bundles = {"walk.json"};  // read back, so it must validate
  config.ppo.num_envs = 24;
  config.model = SmallModel();
  TrainedModel saved = MakeTrainedModel(SmallLayout(), kActions, 1);
  for (auto& group : saved.optimizer->param_groups())
    group.options().set_lr(1.75e-5);
  CheckpointCounters counters;
  counters.iteration = 12;
  counters.samples = 4242;
  SaveCheckpoint(path, config, saved.model, *saved.optimizer, counters,
                 task.initial_states.get(), state_template);

  const SlimCheckpointSummary summary = WriteSlimCheckpoint(path, slim_path);
  EXPECT_EQ(summary.samples, 4242);
  EXPECT_EQ(summary.bytes_before, static_cast<int64_t>(fs::file_size(path)));
  EXPECT_EQ(summary.bytes_after,
            static_cast<int64_t>(fs::file_size(slim_path)));
  EXPECT_LT(summary.bytes_after, summary.bytes_before);

  // What each holds, read without building the task: the counters,
  // config and layout of both, the buffers of the full one only.
  int64_t num_states = 0;
  for (int f = 0; f < buffer.num_frames(); ++f) num_states += buffer.size(f);
  const CheckpointInfo full_info = ReadCheckpointInfo(path);
  const CheckpointInfo slim_info = ReadCheckpointInfo(slim_path);
  for (const CheckpointInfo* info : {&full_info, &slim_info}) {
    EXPECT_EQ(info->counters.iteration, 12);
    EXPECT_EQ(info->counters.samples, 4242);
    EXPECT_EQ(info->counters.learning_rate, 1.75e-5);
    EXPECT_EQ(info->config.ppo.num_envs, 24);
    EXPECT_EQ(info->action_size, kActions);
    EXPECT_EQ(info->layout.num_points, SmallLayout().num_points);
  }
  EXPECT_EQ(full_info.bytes, summary.bytes_before);
  EXPECT_EQ(full_info.num_state_buffers, 1);
  EXPECT_EQ(full_info.num_buffered_states, num_states);
  EXPECT_EQ(slim_info.bytes, summary.bytes_after);
  EXPECT_EQ(slim_info.num_state_buffers, 0);
  EXPECT_EQ(slim_info.num_buffered_states, 0);

  // Networks, normalizer, Adam's moments and rate, counters: as saved.
  TrainedModel loaded = MakeFreshModel(SmallLayout(), kActions, 2);
  InitialStates fresh(*task.reference, character, options.simulation,
                      StateBufferOptions());
  const CheckpointCounters read = LoadCheckpoint(
      slim_path, loaded.model, loaded.optimizer.get(), &fresh, state_template);
  EXPECT_EQ(read.iteration, 12);
  EXPECT_EQ(read.samples, 4242);
  EXPECT_EQ(read.learning_rate, 1.75e-5);
  EXPECT_TRUE(SameTensors(loaded.model->named_parameters(),
                          saved.model->named_parameters()));
  EXPECT_TRUE(
      SameTensors(loaded.model->named_buffers(), saved.model->named_buffers()));
  // Adam's moments too: the next update is the one the saved run makes.
  EXPECT_TRUE(TheNextUpdateIsTheSame(SmallLayout(), saved, loaded));
  // No buffers: a resumed run keeps the task's fresh ones; asking for the
  // buffers alone is an error naming the file.
  EXPECT_EQ(fresh.buffer(0).size(3), fresh_size);
  try {
    LoadCheckpointStateBuffers(slim_path, &fresh, state_template);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(slim_path), std::string::npos) << message;
    EXPECT_NE(message.find("holds no initial-state buffers"), std::string::npos)
        << message;
  }
  // Not a checkpoint: an error naming the file, nothing written.
  const std::string text_path = dir + "/notes.txt";
  std::ofstream(text_path) << "not a checkpoint\n";
  EXPECT_THROW(WriteSlimCheckpoint(text_path, dir + "/out.pt"), InputError);
  EXPECT_THROW(ReadCheckpointInfo(text_path), InputError);
  EXPECT_FALSE(fs::exists(dir + "/out.pt"));
  fs::remove_all(dir);
}

// `checkpoint average`: the networks and normalizers are the element-wise
// mean; the optimizer and counters the last input's; another line's
// networks are refused, naming the file.
TEST(Checkpoint, AveragingCheckpointsOfALineTakesTheMeanOfTheirNetworks) {
  const std::string dir = testing::TempDir("checkpoint_average");
  TrainConfig config;
  config.data.bundles = {"walk.json"};
  config.model = SmallModel();
  std::vector<std::string> paths;
  std::vector<TrainedModel> saved;
  for (int i = 0; i < 3; ++i) {
    saved.push_back(MakeTrainedModel(SmallLayout(), kActions, 10 + i));
    CheckpointCounters counters;
    counters.iteration = 10 * (i + 1);
    counters.samples = 1000 * (i + 1);
    paths.push_back(dir + "/ckpt_" + std::to_string(i) + ".pt");
    SaveCheckpoint(paths.back(), config, saved.back().model,
                   *saved.back().optimizer, counters, nullptr, SimState());
  }
  const std::string out = dir + "/mean.pt";
  // Out of order, as a shell glob lists ckpt_<samples>.pt by text: the
  // newest (most samples) still gives the counters and optimizer.
  const AveragedCheckpointSummary summary =
      AverageCheckpoints({paths[2], paths[0], paths[1]}, out);
  EXPECT_EQ(summary.num_averaged, 3);
  EXPECT_EQ(summary.first_samples, 1000);
  EXPECT_EQ(summary.last_samples, 3000);

  TrainedModel loaded = MakeFreshModel(SmallLayout(), kActions, 99);
  const CheckpointCounters read = LoadCheckpoint(
      out, loaded.model, loaded.optimizer.get(), nullptr, SimState());
  EXPECT_EQ(read.samples, 3000);
  EXPECT_EQ(read.iteration, 30);
  auto expect_mean = [&](auto named_of) {
    for (const auto& named : named_of(*loaded.model)) {
      torch::Tensor sum = torch::zeros_like(named.value());
      for (TrainedModel& model : saved)
        sum += named_of(*model.model)[named.key()];
      EXPECT_TRUE(torch::allclose(named.value(), sum / 3.0, 1e-5, 1e-6))
          << named.key();
    }
  };
  expect_mean([](ActorCriticImpl& m) { return m.named_parameters(); });
  expect_mean([](ActorCriticImpl& m) { return m.named_buffers(); });
  // The weights moved: the mean is none of the inputs.
  EXPECT_FALSE(SameTensors(loaded.model->named_parameters(),
                           saved[0].model->named_parameters()));
  // Adam's moments are the newest input's: a resumed run updates as it would.
  // (The fixed log_std takes no gradient and has none.)
  const std::vector<torch::Tensor> last_parameters =
      saved[2].model->parameters();
  const std::vector<torch::Tensor> mean_parameters = loaded.model->parameters();
  int with_state = 0;
  for (size_t i = 0; i < last_parameters.size(); ++i) {
    const auto* last = AdamState(*saved[2].optimizer, last_parameters[i]);
    const auto* mean = AdamState(*loaded.optimizer, mean_parameters[i]);
    ASSERT_EQ(last == nullptr, mean == nullptr) << i;
    if (last == nullptr) continue;
    ++with_state;
    EXPECT_TRUE(torch::equal(last->exp_avg(), mean->exp_avg())) << i;
    EXPECT_TRUE(torch::equal(last->exp_avg_sq(), mean->exp_avg_sq())) << i;
  }
  EXPECT_EQ(with_state, static_cast<int>(last_parameters.size()) - 1);

  // Another line's networks (a wider policy), a file that is no checkpoint,
  // and a single input are refused; nothing is written.
  TrainConfig wider = config;
  wider.model.policy_hidden = {48};
  torch::manual_seed(5);
  ActorCritic other(SmallLayout(), wider.model, kActions);
  torch::optim::Adam other_optimizer(other->parameters(),
                                     torch::optim::AdamOptions(1e-3));
  const std::string other_path = dir + "/other.pt";
  SaveCheckpoint(other_path, wider, other, other_optimizer,
                 CheckpointCounters(), nullptr, SimState());
  const std::string refused = dir + "/refused.pt";
  ExpectInputErrorNaming(other_path, [&] {
    AverageCheckpoints({other_path, paths[2]}, refused);
  });
  const std::string text_path = dir + "/notes.txt";
  std::ofstream(text_path) << "not a checkpoint\n";
  ExpectInputErrorNaming(text_path, [&] {
    AverageCheckpoints({paths[0], text_path}, refused);
  });
  EXPECT_THROW(AverageCheckpoints({paths[0]}, refused), ConfigError);
  EXPECT_FALSE(fs::exists(refused));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace m2d
