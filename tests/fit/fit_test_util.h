// tests: helpers shared by the fit tests.
#ifndef MIMIC2D_TESTS_FIT_FIT_TEST_UTIL_H_
#define MIMIC2D_TESTS_FIT_FIT_TEST_UTIL_H_

#include <memory>

#include "sim/sim_test_util.h"

namespace m2d::testing {

// The humanoid on the flat scene, loaded once per test binary.
inline std::shared_ptr<const Character> Humanoid() {
  static const std::shared_ptr<const Character> character =
      LoadHumanoid("flat");
  return character;
}

// The dog on the flat scene, loaded once per test binary.
inline std::shared_ptr<const Character> Dog() {
  static const std::shared_ptr<const Character> character = LoadDog("flat");
  return character;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_FIT_FIT_TEST_UTIL_H_
