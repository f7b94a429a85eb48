// rl: LibTorch archives on disk, checked — written atomically behind a
// checksum trailer and read back only when the trailer and the archive's
// format name match. Every checkpoint of rl/ and gen/ goes through this.
#ifndef MIMIC2D_RL_ARCHIVE_FILE_H_
#define MIMIC2D_RL_ARCHIVE_FILE_H_

#include <torch/torch.h>

#include <string>

#include "common/error.h"

namespace m2d {

// Writes `archive` (which holds "format" = `format`, written here) to a
// temporary file next to `path` and renames it over `path`. InputError
// naming `path` when serialization or writing fails; the previous file is
// then unchanged.
void WriteArchiveFile(const std::string& path, const std::string& format,
                      torch::serialize::OutputArchive& archive);

// Opens a file WriteArchiveFile wrote with the same `format`. InputError
// naming `path` for a missing or damaged trailer, a checksum mismatch, an
// unreadable archive or another format.
torch::serialize::InputArchive ReadArchiveFile(const std::string& path,
                                               const std::string& format);

// Runs `read`, turning whatever LibTorch throws for a malformed archive
// (c10::Error, std::out_of_range, std::bad_alloc, ...) into an InputError
// naming `path` and `problem`.
template <typename Read>
auto NamingArchiveErrors(const std::string& path, const std::string& problem,
                         Read read) -> decltype(read()) {
  try {
    return read();
  } catch (const InputError&) {
    throw;
  } catch (const ConfigError& e) {
    throw InputError(path, problem + " (" + e.what() + ")");
  } catch (const c10::Error& e) {
    throw InputError(path, problem + " (" + e.what_without_backtrace() + ")");
  } catch (const std::exception& e) {
    throw InputError(path, problem + " (" + e.what() + ")");
  }
}

}  // namespace m2d

#endif  // MIMIC2D_RL_ARCHIVE_FILE_H_
