// The collector's bootstrap at an episode's end: a time limit's cut adds
// gamma * V(last observation) to the last reward, reaching the reference's
// last frame adds nothing unless agent.bootstrap_at_reference_end says so.
#include "rl/collector.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "env/env_fixture.h"
#include "test_paths.h"

namespace m2d {
namespace {

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";
constexpr float kCriticValue = 100.0f;  // everywhere
constexpr double kDiscount = 0.99;

// A critic that says kCriticValue whatever it observes: every weight of its
// head zero, the last layer's bias kCriticValue.
void MakeConstantCritic(ActorCritic& model) {
  torch::NoGradGuard no_grad;
  torch::Tensor last_bias;
  for (auto& item : model->named_parameters()) {
    if (item.key().rfind("critic.", 0) != 0) continue;
    item.value().zero_();
    if (item.key().size() > 5 &&
        item.key().compare(item.key().size() - 5, 5, ".bias") == 0)
      last_bias = item.value();
  }
  last_bias.fill_(kCriticValue);
}

// How the episodes that ended in one collection were bootstrapped.
struct EndCounts {
  int time_limit = 0, time_limit_bootstrapped = 0;
  int reference_end = 0, reference_end_bootstrapped = 0;
};

// Collects 60 steps of 4 walk environments (1-s clip, 5-step time limit,
// zero-mean actions, no early exit) and matches every done row to the
// episode it finished.
EndCounts CollectEnds(const std::string& walk_path,
                      bool bootstrap_at_reference_end,
                      CollectionMode collection) {
  EndCounts counts;
  testing::WalkTask task = testing::MakeWalkTask(walk_path, 1.0);
  task.options.early_exit = false;
  task.options.max_episode_s = 5.0 / task.options.simulation.control_hz;
  VecEnv envs(task.character, task.reference, task.initial_states, task.options,
              4, 11, 1);
  PpoOptions options;
  options.num_envs = envs.num_envs();
  options.steps_per_env = 60;
  options.discount = kDiscount;
  options.bootstrap_at_reference_end = bootstrap_at_reference_end;
  options.collection = collection;
  torch::manual_seed(3);
  ActorCritic model(envs.layout(), ModelOptions(), envs.action_size());
  MakeConstantCritic(model);
  RolloutCollector collector(envs, options, at::detail::createCPUGenerator(5));
  RolloutStorage storage(options.steps_per_env, options.num_envs,
                         envs.observation_size(), envs.action_size());
  envs.Reset();
  std::vector<FinishedEpisode> finished;
  collector.Collect(model, nullptr, storage, &finished);

  // Each env's done rows, in time order, are its finished episodes in order.
  std::vector<std::vector<EpisodeStats>> episodes(envs.num_envs());
  for (const FinishedEpisode& f : finished) episodes[f.env].push_back(f.stats);
  for (int i = 0; i < envs.num_envs(); ++i) {
    size_t next = 0;
    for (int t = 0; t < options.steps_per_env; ++t) {
      if (storage.dones[t][i].item<float>() == 0.0f) continue;
      EXPECT_LT(next, episodes[i].size());
      if (next >= episodes[i].size()) break;
      const EpisodeStats& episode = episodes[i][next++];
      EXPECT_FALSE(episode.failed);
      const int last_frame =
          task.reference->views()[episode.view_index].num_frames - 1;
      // The step's own reward is at most 1; the bootstrap adds 99.
      const bool bootstrapped = storage.rewards[t][i].item<float>() > 50.0f;
      if (episode.start_frame + episode.steps >= last_frame) {
        ++counts.reference_end;
        counts.reference_end_bootstrapped += bootstrapped;
      } else {
        EXPECT_EQ(episode.steps, 5);
        ++counts.time_limit;
        counts.time_limit_bootstrapped += bootstrapped;
      }
    }
    EXPECT_EQ(next, episodes[i].size()) << "env " << i;
  }
  return counts;
}

// Time-limit ends always carry gamma * V; clip ends only with the setting.
void ExpectEndsBootstrapped(bool bootstrap_at_reference_end,
                            CollectionMode collection) {
  M2D_REQUIRE_SHARED(path, kWalk);
  EndCounts counts = CollectEnds(path, bootstrap_at_reference_end, collection);
  ASSERT_GE(counts.time_limit, 5);
  ASSERT_GE(counts.reference_end, 2);
  EXPECT_EQ(counts.time_limit_bootstrapped, counts.time_limit);
  EXPECT_EQ(counts.reference_end_bootstrapped,
            bootstrap_at_reference_end ? counts.reference_end : 0);
}

class Collector : public ::testing::TestWithParam<CollectionMode> {};

TEST_P(Collector, TheReferencesEndAddsNoValueByDefault) {
  ExpectEndsBootstrapped(PpoOptions().bootstrap_at_reference_end, GetParam());
  EXPECT_FALSE(PpoOptions().bootstrap_at_reference_end);
}

TEST_P(Collector, BootstrapAtReferenceEndAddsTheValueAsATimeLimitDoes) {
  ExpectEndsBootstrapped(true, GetParam());
}

INSTANTIATE_TEST_SUITE_P(BothCollections, Collector,
                         ::testing::Values(CollectionMode::kBatched,
                                           CollectionMode::kPerThread),
                         [](const auto& info) {
                           return info.param == CollectionMode::kBatched
                                      ? std::string("Batched")
                                      : std::string("PerThread");
                         });

}  // namespace
}  // namespace m2d
