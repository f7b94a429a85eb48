// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_SUBPROCESS_H_
#define MIMIC2D_RENDER_SUBPROCESS_H_

#include <sys/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace m2d {

struct ProcessResult {
  int exit_code = 0;   // 128 + signal number when killed by a signal
  std::string output;  // stdout and stderr, interleaved
  bool ok() const { return exit_code == 0; }
};

// A child process started without a shell (argv[0] is looked up in PATH),
// fed through a pipe on its stdin. Its stdout and stderr go to a temporary
// file (so a chatty child never blocks), read back by Wait().
class PipedProcess {
 public:
  // Throws std::runtime_error naming argv[0] when it cannot be started.
  explicit PipedProcess(const std::vector<std::string>& argv);
  // Stops a child that was not waited for (SIGTERM) and reaps it.
  ~PipedProcess();
  PipedProcess(const PipedProcess&) = delete;
  PipedProcess& operator=(const PipedProcess&) = delete;

  // Writes all `size` bytes; false when the child closed its input (it
  // exited; Wait() tells why). Never raises SIGPIPE.
  bool Write(const void* bytes, size_t size);
  // Closes the child's stdin and waits for it to exit.
  ProcessResult Wait();

 private:
  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  std::string output_path_;
};

// Runs `argv` to completion with an empty stdin.
ProcessResult RunProcess(const std::vector<std::string>& argv);

// True when `program` is an executable file in PATH (or a path to one).
bool ProgramAvailable(const std::string& program);

// A fresh folder under the system's temporary folder for a child's scratch
// files (scripts, data), removed with everything in it on destruction.
class ScopedTempFolder {
 public:
  explicit ScopedTempFolder(const std::string& prefix);
  ~ScopedTempFolder();
  ScopedTempFolder(const ScopedTempFolder&) = delete;
  ScopedTempFolder& operator=(const ScopedTempFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace m2d

#endif  // MIMIC2D_RENDER_SUBPROCESS_H_
