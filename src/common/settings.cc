#include "common/settings.h"

#include <cmath>
#include <sstream>

namespace m2d {
namespace {

std::string Bound(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

std::string Range::ToString() const {
  if (IsAny()) return "";
  return std::string(min_open ? "(" : "[") + Bound(min) + ", " + Bound(max) +
         (max_open ? ")" : "]");
}

void RangeChecker::Check(const char* key, double value,
                         const Range& range) const {
  if (range.Contains(value)) return;
  std::ostringstream message;
  message << section_ << "." << key << " must be in " << range.ToString()
          << " (is " << value << ")";
  throw ConfigError(message.str());
}

}  // namespace m2d
