// common: settings declared once. An options struct lists its fields in a
// static VisitFields(self, visitor), right below their declarations: key,
// member, the range it may take and what it means. Range checks
// (CheckRanges, called by Validate()), reading and writing YAML
// (yaml_fields.h: ReadFields, WriteFields) and the reference table of every
// setting (yaml_fields.h: AppendSettingRows) all walk that one list.
//
//   struct RunOptions {
//     int env_threads = 2;  // OpenMP threads stepping environments
//     template <typename Self, typename Visitor>
//     static void VisitFields(Self& self, Visitor& v) {
//       v("env_threads", self.env_threads, Range::Closed(1, 1024),
//         "OpenMP threads stepping environments");
//     }
//   };
//
// A visitor is called as v(key, member, range, meaning) per field and
// v.Nested(key, member) for a sub-section (a struct with its own
// VisitFields); a struct's fields may also be spliced into its parent's
// section by calling the member's VisitFields with the same visitor.
// Enums used as settings provide, found by argument-dependent lookup,
// `const char* SettingName(E)`, `bool ParseSetting(const std::string&, E*)`
// and `std::string SettingChoices(E)` ("a, b, c").
#ifndef MIMIC2D_COMMON_SETTINGS_H_
#define MIMIC2D_COMMON_SETTINGS_H_

#include <initializer_list>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "common/error.h"

namespace m2d {

// ParseSetting for an enum that has SettingName: the one of `values` named
// `text`; false when none is.
template <typename E>
bool ParseSettingByName(const std::string& text,
                        std::initializer_list<E> values, E* value) {
  for (E known : values) {
    if (text == SettingName(known)) {
      *value = known;
      return true;
    }
  }
  return false;
}

// The values a numeric setting may take: an interval whose ends are each
// open or closed (an infinite end is open). NaN is in no range.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = true;
  bool max_open = true;

  static Range Any() { return {}; }
  static Range AtLeast(double low) { return {low, Inf(), false, true}; }
  static Range Above(double low) { return {low, Inf(), true, true}; }
  static Range Closed(double low, double high) {
    return {low, high, false, false};
  }
  static Range Open(double low, double high) { return {low, high, true, true}; }

  bool Contains(double value) const {
    return (min_open ? value > min : value >= min) &&
           (max_open ? value < max : value <= max);
  }
  bool IsAny() const { return min == -Inf() && max == Inf(); }
  // "[1, 65536]", "(0, inf)", "[0, 1)"; "" for any value.
  std::string ToString() const;

 private:
  static double Inf() { return std::numeric_limits<double>::infinity(); }
};

template <typename T>
struct IsVector : std::false_type {};
template <typename T>
struct IsVector<std::vector<T>> : std::true_type {};

// Checks every numeric field (and each element of a numeric list) against
// its range; ConfigError "<section>.<key> must be in <range>" otherwise.
class RangeChecker {
 public:
  explicit RangeChecker(std::string section) : section_(std::move(section)) {}

  template <typename T>
  void operator()(const char* key, const T& value, const Range& range,
                  const char* /*meaning*/) const {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      Check(key, static_cast<double>(value), range);
    } else if constexpr (IsVector<T>::value) {
      if constexpr (std::is_arithmetic_v<typename T::value_type>) {
        for (const auto& element : value)
          Check(key, static_cast<double>(element), range);
      }
    }
  }
  template <typename Options>
  void Nested(const char* key, const Options& options) const {
    RangeChecker inner(section_ + "." + key);
    Options::VisitFields(options, inner);
  }

 private:
  void Check(const char* key, double value, const Range& range) const;
  std::string section_;
};

// Range checks of `options` (ConfigError naming "<section>.<key>").
template <typename Options>
void CheckRanges(const Options& options, const std::string& section) {
  RangeChecker checker(section);
  Options::VisitFields(options, checker);
}

}  // namespace m2d

#endif  // MIMIC2D_COMMON_SETTINGS_H_
