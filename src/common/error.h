// common: errors, file I/O and small utilities shared by every folder.
#ifndef MIMIC2D_COMMON_ERROR_H_
#define MIMIC2D_COMMON_ERROR_H_

#include <stdexcept>
#include <string>

namespace m2d {

// Bad user input: a malformed file, a wrong shape, an unknown name, NaN.
// `what()` reads "<source>: <problem>" so the user knows which file to fix.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& source, const std::string& problem)
      : std::runtime_error(source.empty() ? problem : source + ": " + problem),
        source_(source),
        problem_(problem) {}

  const std::string& source() const { return source_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string source_;
  std::string problem_;
};

// A setting that fails validation (an Options struct's Validate()).
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace m2d

#endif  // MIMIC2D_COMMON_ERROR_H_
