// common: checked access to JSON fields, so that every reader reports a
// malformed file as "<file>: <where>: <problem>" instead of crashing.
#ifndef MIMIC2D_COMMON_JSON_FIELDS_H_
#define MIMIC2D_COMMON_JSON_FIELDS_H_

#include <nlohmann/json.hpp>
#include <string>

namespace m2d {

// A position inside a JSON document: the file and a path like
// "views[2].clip.keypoints[10]".
class JsonCursor {
 public:
  JsonCursor(const nlohmann::json& value, std::string source,
             std::string where = "")
      : value_(&value), source_(std::move(source)), where_(std::move(where)) {}

  const nlohmann::json& value() const { return *value_; }
  const std::string& source() const { return source_; }
  const std::string& where() const { return where_; }

  // The object member `key`; InputError when absent or not an object.
  JsonCursor Field(const std::string& key) const;
  bool Has(const std::string& key) const;
  // Array element `index`; InputError when out of range or not an array.
  JsonCursor At(size_t index) const;

  // Array size; InputError unless an array (of `expected` size when >= 0).
  size_t ArraySize(long expected = -1) const;
  // A finite number (null or non-finite is an error).
  double Number() const;
  // A number that may be null (returned as NaN).
  double NumberOrNan() const;
  long Integer() const;
  std::string String() const;
  bool Boolean() const;

  // InputError at this position.
  [[noreturn]] void Fail(const std::string& problem) const;

 private:
  const nlohmann::json* value_;
  std::string source_;
  std::string where_;
};

}  // namespace m2d

#endif  // MIMIC2D_COMMON_JSON_FIELDS_H_
