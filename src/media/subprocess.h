// media: images and video in and out — RGB images, PNG, video decoding and
// MP4 encoding through the ffmpeg binary, child processes; shared by
// rendering and detection.
#ifndef MIMIC2D_MEDIA_SUBPROCESS_H_
#define MIMIC2D_MEDIA_SUBPROCESS_H_

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

// Which of the child's streams the pipe is.
enum class PipeDirection {
  kToChild,    // we write its stdin; its stdout and stderr go to the file
  kFromChild,  // we read its stdout; its stdin is empty, stderr to the file
};

// A child process started without a shell (argv[0] is looked up in PATH),
// fed through a pipe on its stdin or read through one on its stdout. What
// else it prints goes to a temporary file (so a chatty child never
// blocks), read back by Wait().
class PipedProcess {
 public:
  // Throws std::runtime_error naming argv[0] when it cannot be started.
  explicit PipedProcess(const std::vector<std::string>& argv,
                        PipeDirection direction = PipeDirection::kToChild);
  // Stops a child that was not waited for (SIGTERM) and reaps it.
  ~PipedProcess();
  PipedProcess(const PipedProcess&) = delete;
  PipedProcess& operator=(const PipedProcess&) = delete;

  // Writes all `size` bytes; false when the child closed its input (it
  // exited; Wait() tells why). Never raises SIGPIPE.
  bool Write(const void* bytes, size_t size);
  // kFromChild: reads until `size` bytes or the end of the child's output;
  // returns how many were read.
  size_t Read(void* bytes, size_t size);
  // Closes the child's stdin and waits for it to exit.
  ProcessResult Wait();

 private:
  pid_t pid_ = -1;
  int stdin_fd_ = -1;   // kToChild: the write end of the child's stdin
  int stdout_fd_ = -1;  // kFromChild: the read end of the child's stdout
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

#endif  // MIMIC2D_MEDIA_SUBPROCESS_H_
