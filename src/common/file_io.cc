#include "common/file_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace m2d {

std::string ReadFileText(const std::string& path) {
  // A folder or a device (/dev/null) opens and reads as empty: say so
  // instead of handing an empty document to a parser that keeps defaults.
  std::error_code ec;
  if (std::filesystem::exists(path, ec) &&
      !std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path, std::filesystem::is_directory(path, ec)
                               ? "is a folder, not a file"
                               : "is not a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    std::string problem =
        std::string("cannot open file (") + std::strerror(error) + ")";
    // Paths in configs are read from the working directory (the shipped
    // ones from the repository's root): say which, for a command started
    // elsewhere.
    if (error == ENOENT && std::filesystem::path(path).is_relative()) {
      problem += "; relative paths are read from the working directory " +
                 std::filesystem::current_path(ec).string();
    }
    throw InputError(path, problem);
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void WriteFileAtomic(const std::string& path, const std::string& contents) {
  // Outline: write a sibling temp file, fsync it, rename over the target,
  // fsync the folder so the rename itself survives a power loss.
  std::filesystem::path target(path);
  std::filesystem::path folder = target.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  std::string temp = path + ".tmp." + std::to_string(::getpid());

  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) {
    throw InputError(
        path, std::string("cannot write (") + std::strerror(errno) + ")");
  }
  const char* data = contents.data();
  size_t remaining = contents.size();
  while (remaining > 0) {
    ssize_t written = ::write(fd, data, remaining);
    if (written < 0) {
      if (errno == EINTR) continue;
      int saved = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      throw InputError(
          path, std::string("write failed (") + std::strerror(saved) + ")");
    }
    data += written;
    remaining -= static_cast<size_t>(written);
  }
  ::fsync(fd);
  ::close(fd);
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    int saved = errno;
    ::unlink(temp.c_str());
    throw InputError(
        path, std::string("rename failed (") + std::strerror(saved) + ")");
  }
  int dir_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

std::string WritableFileProblem(const std::string& path) {
  // Outline: the path itself must not be a folder; the nearest existing
  // ancestor (the working directory for a relative path whose folders are
  // all missing) must be a folder this process may write into.
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty()) return "no path given";
  if (fs::is_directory(path, ec)) return "is a folder, not a file";
  fs::path folder = fs::path(path).parent_path();
  while (!folder.empty() && !fs::exists(folder, ec))
    folder = folder.parent_path();
  if (folder.empty()) folder = ".";
  if (!fs::is_directory(folder, ec))
    return folder.string() + " is a file, not a folder";
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    return "folder " + folder.string() + " is not writable (" +
           std::strerror(errno) + ")";
  return "";
}

nlohmann::json ReadJsonFile(const std::string& path) {
  std::string text = ReadFileText(path);
  // No file of ours nests deeper than a few levels; a document nested
  // thousands deep (fuzzing found a COCO bbox 50,000 deep) would exhaust
  // the stack in code that walks it recursively.
  constexpr int kMaxDepth = 64;
  const nlohmann::json::parser_callback_t limit_depth =
      [&path](int depth, nlohmann::json::parse_event_t,
              nlohmann::json&) -> bool {
    if (depth > kMaxDepth) {
      throw InputError(path, "JSON nested more than " +
                                 std::to_string(kMaxDepth) + " levels deep");
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text, limit_depth);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("malformed JSON: ") + e.what());
  }
}

void WriteJsonFileAtomic(const std::string& path, const nlohmann::json& json,
                         int indent) {
  WriteFileAtomic(path, json.dump(indent) + "\n");
}

YAML::Node ReadYamlFile(const std::string& path) {
  std::string text = ReadFileText(path);
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path, std::string("malformed YAML: ") + e.what());
  }
}

std::string ParentDirectory(const std::string& path) {
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

std::string ResolveRelative(const std::string& base_file,
                            const std::string& relative) {
  std::filesystem::path rel(relative);
  if (rel.is_absolute()) return relative;
  return (std::filesystem::path(ParentDirectory(base_file)) / rel).string();
}

}  // namespace m2d
