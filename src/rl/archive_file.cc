#include "rl/archive_file.h"

#include <cstring>
#include <filesystem>
#include <sstream>

#include "common/file_io.h"
#include "common/hash.h"

namespace m2d {
namespace {

// A file is LibTorch's zip archive followed by a trailer: this magic and a
// 64-bit FNV-1a hash of the archive bytes. The archive stores tensors
// uncompressed and LibTorch 1.13 does not check its CRCs, so a flipped bit
// would otherwise load as a silently different weight. The trailer is
// required: LibTorch's archive reader is not safe on damaged files (fuzzing
// crashed its TorchScript type parser with a SEGV within a few hundred
// mutations, docs/reliability.md), so no byte reaches it unverified.
constexpr char kTrailerMagic[8] = {'M', '2', 'D', 'C', 'K', 'S', 'U', 'M'};
constexpr size_t kTrailerSize = sizeof(kTrailerMagic) + sizeof(uint64_t);

}  // namespace

void WriteArchiveFile(const std::string& path, const std::string& format,
                      torch::serialize::OutputArchive& archive) {
  archive.write("format", c10::IValue(format));
  // Serialized in memory, then written atomically: LibTorch writing to a
  // full disk aborted the process (its zip writer throws from a destructor)
  // and left a partial file; WriteFileAtomic reports the error by name and
  // leaves the previous file in place.
  std::ostringstream bytes;
  try {
    archive.save_to(bytes);
  } catch (const c10::Error& e) {
    throw InputError(path, "cannot serialize checkpoint: " +
                               std::string(e.what_without_backtrace()));
  }
  std::string contents = bytes.str();
  const uint64_t hash = Fnv1a64(contents.data(), contents.size());
  contents.append(kTrailerMagic, sizeof(kTrailerMagic));
  contents.append(reinterpret_cast<const char*>(&hash), sizeof(hash));
  const std::string folder = ParentDirectory(path);
  if (!std::filesystem::is_directory(folder)) {
    throw InputError(
        path, "cannot write checkpoint: folder " + folder + " does not exist");
  }
  try {
    WriteFileAtomic(path, contents);
  } catch (const InputError& e) {
    throw InputError(path, "cannot write checkpoint: " + e.problem() +
                               "; the previous checkpoint is unchanged");
  }
}

torch::serialize::InputArchive ReadArchiveFile(const std::string& path,
                                               const std::string& format) {
  const std::string contents = ReadFileText(path);
  if (contents.size() < kTrailerSize ||
      std::memcmp(contents.data() + contents.size() - kTrailerSize,
                  kTrailerMagic, sizeof(kTrailerMagic)) != 0) {
    throw InputError(path,
                     "not a mimic2d checkpoint, or a damaged one: it does not "
                     "end in mimic2d's checksum trailer (a partly copied "
                     "file, or another program's)");
  }
  const size_t archive_size = contents.size() - kTrailerSize;
  uint64_t stored = 0;
  std::memcpy(&stored, contents.data() + archive_size + sizeof(kTrailerMagic),
              sizeof(stored));
  if (Fnv1a64(contents.data(), archive_size) != stored) {
    throw InputError(path,
                     "checkpoint is corrupt (its checksum does not match "
                     "its contents: a damaged or partly copied file)");
  }
  torch::serialize::InputArchive archive;
  NamingArchiveErrors(path, "not a readable checkpoint", [&] {
    archive.load_from(contents.data(), archive_size);
  });
  c10::IValue stored_format;
  const bool has_format =
      NamingArchiveErrors(path, "not a mimic2d checkpoint", [&] {
        return archive.try_read("format", stored_format) &&
               stored_format.isString();
      });
  if (!has_format) throw InputError(path, "not a mimic2d checkpoint");
  if (stored_format.toStringRef() != format) {
    throw InputError(path, "is a " + stored_format.toStringRef() +
                               " file, expected " + format);
  }
  return archive;
}

}  // namespace m2d
