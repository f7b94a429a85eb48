#include "media/subprocess.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace m2d {
namespace {

std::string ErrnoText(int error) { return std::strerror(error); }

// Writes to a pipe with SIGPIPE blocked on this thread, so a reader that
// went away shows up as EPIPE instead of killing the process; a SIGPIPE
// raised meanwhile is consumed before the mask is restored.
bool WriteWithoutSigpipe(int fd, const char* bytes, size_t size) {
  sigset_t sigpipe, previous;
  sigemptyset(&sigpipe);
  sigaddset(&sigpipe, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &sigpipe, &previous);
  bool ok = true;
  while (size > 0) {
    ssize_t written = ::write(fd, bytes, size);
    if (written < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    bytes += written;
    size -= static_cast<size_t>(written);
  }
  if (!ok && errno == EPIPE) {
    const timespec no_wait = {0, 0};
    while (sigtimedwait(&sigpipe, nullptr, &no_wait) == SIGPIPE) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return ok;
}

}  // namespace

PipedProcess::PipedProcess(const std::vector<std::string>& argv,
                           PipeDirection direction) {
  if (argv.empty()) throw std::invalid_argument("PipedProcess: empty argv");
  char output_template[] = "/tmp/mimic2d_process_XXXXXX";
  const int output_fd = mkostemp(output_template, O_CLOEXEC);
  if (output_fd < 0) {
    throw std::runtime_error("cannot create a temporary file for " + argv[0] +
                             "'s output: " + ErrnoText(errno));
  }
  output_path_ = output_template;
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) {
    ::close(output_fd);
    std::filesystem::remove(output_path_);
    throw std::runtime_error("cannot create a pipe for " + argv[0]);
  }
  const bool to_child = direction == PipeDirection::kToChild;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // dup2 clears close-on-exec on the child's 0, 1 and 2 only.
  if (to_child) {
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, output_fd, STDOUT_FILENO);
  } else {
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null",
                                     O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  }
  posix_spawn_file_actions_adddup2(&actions, output_fd, STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& arg : argv)
    args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const int error = posix_spawnp(&pid_, argv[0].c_str(), &actions, nullptr,
                                 args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  // Keep our end only.
  const int ours = to_child ? pipe_fds[1] : pipe_fds[0];
  ::close(to_child ? pipe_fds[0] : pipe_fds[1]);
  ::close(output_fd);
  if (error != 0) {
    ::close(ours);
    std::filesystem::remove(output_path_);
    pid_ = -1;
    throw std::runtime_error("cannot run '" + argv[0] +
                             "': " + ErrnoText(error));
  }
  (to_child ? stdin_fd_ : stdout_fd_) = ours;
}

PipedProcess::~PipedProcess() {
  if (stdin_fd_ >= 0) ::close(stdin_fd_);
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (!output_path_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(output_path_, ignored);
  }
}

bool PipedProcess::Write(const void* bytes, size_t size) {
  if (stdin_fd_ < 0) return false;
  return WriteWithoutSigpipe(stdin_fd_, static_cast<const char*>(bytes), size);
}

size_t PipedProcess::Read(void* bytes, size_t size) {
  if (stdout_fd_ < 0) return 0;
  char* out = static_cast<char*>(bytes);
  size_t total = 0;
  while (total < size) {
    const ssize_t got = ::read(stdout_fd_, out + total, size - total);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    total += static_cast<size_t>(got);
  }
  return total;
}

ProcessResult PipedProcess::Wait() {
  if (pid_ <= 0) throw std::logic_error("PipedProcess::Wait called twice");
  if (stdin_fd_ >= 0) {
    ::close(stdin_fd_);
    stdin_fd_ = -1;
  }
  // A reader that stops early closes its end: the child gets SIGPIPE or
  // EPIPE and exits.
  if (stdout_fd_ >= 0) {
    ::close(stdout_fd_);
    stdout_fd_ = -1;
  }
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0) {
    if (errno != EINTR) break;
  }
  pid_ = -1;
  ProcessResult result;
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.exit_code = 128 + WTERMSIG(status);
  } else {
    result.exit_code = -1;
  }
  std::ifstream output(output_path_, std::ios::binary);
  std::ostringstream text;
  text << output.rdbuf();
  result.output = text.str();
  std::error_code ignored;
  std::filesystem::remove(output_path_, ignored);
  output_path_.clear();
  return result;
}

ProcessResult RunProcess(const std::vector<std::string>& argv) {
  PipedProcess process(argv);
  return process.Wait();
}

bool ProgramAvailable(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    return ::access(program.c_str(), X_OK) == 0;
  }
  const char* path = std::getenv("PATH");
  std::stringstream folders(path != nullptr ? path : "/usr/bin:/bin");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) folder = ".";
    const std::string candidate = folder + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

ScopedTempFolder::ScopedTempFolder(const std::string& prefix) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("cannot create a temporary folder " + pattern +
                             ": " + ErrnoText(errno));
  }
  path_ = pattern;
}

ScopedTempFolder::~ScopedTempFolder() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

}  // namespace m2d
