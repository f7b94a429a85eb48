// A training config for bookkeeping tests: a 1 s walk bundle written into
// `dir`, tiny networks, one env thread, a checkpoint only when asked for or
// at the end. Callers set the batch, seed and what they test, then
// Validate().
#ifndef MIMIC2D_TESTS_RL_TINY_WALK_CONFIG_H_
#define MIMIC2D_TESTS_RL_TINY_WALK_CONFIG_H_

#include <string>

#include "env/env_fixture.h"
#include "rl/train_config.h"

namespace m2d::testing {

inline TrainConfig TinyWalkConfig(const std::string& walk_path,
                                  const std::string& dir) {
  TrainConfig config;
  config.data.character_config = SourcePath("assets/characters/humanoid.yaml");
  auto character = LoadCharacterForSimulation(config.data.character_config,
                                              "flat", config.env.simulation);
  config.data.bundles = {dir + "/walk1s.json"};
  WriteBundle(config.data.bundles[0],
              MakeWalkBundle(walk_path, *character, 1.0));
  config.model.encoder_hidden = {16};
  config.model.encoder_features = 8;
  config.model.policy_hidden = {32};
  config.model.critic_hidden = {32};
  config.run.run_dir = dir + "/run";
  config.run.env_threads = 1;
  config.run.checkpoint_minutes = 60.0;
  return config;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_RL_TINY_WALK_CONFIG_H_
