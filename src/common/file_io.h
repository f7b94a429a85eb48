// common: reading and atomically writing files; JSON and YAML at the edge.
#ifndef MIMIC2D_COMMON_FILE_IO_H_
#define MIMIC2D_COMMON_FILE_IO_H_

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>
#include <string>

namespace m2d {

// Whole file as bytes; InputError naming the path when it cannot be read.
std::string ReadFileText(const std::string& path);

// Writes `contents` to `path` atomically: a temporary file in the same folder
// is written, flushed to disk and renamed over `path`, so a crash or kill
// leaves either the old file or the new one, never a torn one.
void WriteFileAtomic(const std::string& path, const std::string& contents);

// Why no file could be written at `path` by WriteFileAtomic, or "" when
// one could: the path is a folder, the nearest existing folder above it is
// a file, or that folder is not writable (missing folders are created on
// write). For checking outputs before the work that produces them.
std::string WritableFileProblem(const std::string& path);

// Parses JSON; InputError naming the path and the parser's position.
nlohmann::json ReadJsonFile(const std::string& path);
void WriteJsonFileAtomic(const std::string& path, const nlohmann::json& json,
                         int indent = -1);

// Parses YAML; InputError naming the path and the line.
YAML::Node ReadYamlFile(const std::string& path);

// Directory of `path` ("." when it has none), for resolving relative paths.
std::string ParentDirectory(const std::string& path);
// `relative` interpreted relative to the folder holding `base_file`.
std::string ResolveRelative(const std::string& base_file,
                            const std::string& relative);

}  // namespace m2d

#endif  // MIMIC2D_COMMON_FILE_IO_H_
