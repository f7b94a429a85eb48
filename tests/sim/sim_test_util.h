// tests: helpers shared by the sim tests (humanoid and dog asset paths,
// actions).
#ifndef MIMIC2D_TESTS_SIM_SIM_TEST_UTIL_H_
#define MIMIC2D_TESTS_SIM_SIM_TEST_UTIL_H_

#include <string>
#include <vector>

#include "sim/simulation.h"
#include "test_paths.h"

namespace m2d::testing {

inline std::string HumanoidConfigPath() {
  return SourcePath("assets/characters/humanoid.yaml");
}

inline std::shared_ptr<const Character> LoadHumanoid(
    const std::string& scene, const SimulationOptions& options = {}) {
  return LoadCharacterForSimulation(HumanoidConfigPath(), scene, options);
}

inline std::string DogConfigPath() {
  return SourcePath("assets/characters/dog.yaml");
}

// The DeepMimic dog3d quadruped (assets/characters/dog.yaml).
inline std::shared_ptr<const Character> LoadDog(
    const std::string& scene, const SimulationOptions& options = {}) {
  return LoadCharacterForSimulation(DogConfigPath(), scene, options);
}

// The normalized action whose PD target is `angle_rad` for every hinge.
inline std::vector<float> ActionsForAngles(const Character& character,
                                           const std::vector<double>& angles) {
  std::vector<float> actions(character.num_actions());
  for (int i = 0; i < character.num_actions(); ++i) {
    const ActuatedHinge& hinge = character.hinges()[i];
    actions[i] = static_cast<float>((angles[i] - hinge.target_mid_rad) /
                                    hinge.target_half_range_rad);
  }
  return actions;
}

// Actions holding every hinge at 0 (the standing reference pose).
inline std::vector<float> StandingActions(const Character& character) {
  return ActionsForAngles(character,
                          std::vector<double>(character.num_actions(), 0.0));
}

// The character's hinge angles in the simulation's current state.
inline std::vector<double> HingeAngles(const Simulation& sim) {
  std::vector<double> angles;
  for (const ActuatedHinge& hinge : sim.character().hinges()) {
    angles.push_back(sim.data()->qpos[hinge.qpos_address]);
  }
  return angles;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_SIM_SIM_TEST_UTIL_H_
