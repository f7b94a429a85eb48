// tests: running a shell command from a CLI test and reading what it said.
#ifndef MIMIC2D_TESTS_CLI_CLI_TEST_UTIL_H_
#define MIMIC2D_TESTS_CLI_CLI_TEST_UTIL_H_

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace m2d::testing {

struct CommandResult {
  int exit_code = -1;  // -1: did not exit normally
  std::string output;  // stdout and stderr
};

// Runs `command` with sh, stderr folded into stdout.
inline CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr)
    result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// The mimic2d binary under test with `arguments`.
inline CommandResult RunMimic2d(const std::string& arguments) {
  return RunCommand(std::string(MIMIC2D_BINARY) + " " + arguments);
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_CLI_CLI_TEST_UTIL_H_
