#include "common/json_fields.h"

#include <cmath>

#include "common/error.h"

namespace m2d {

void JsonCursor::Fail(const std::string& problem) const {
  throw InputError(source_, where_.empty() ? problem : where_ + ": " + problem);
}

bool JsonCursor::Has(const std::string& key) const {
  return value_->is_object() && value_->contains(key);
}

JsonCursor JsonCursor::Field(const std::string& key) const {
  if (!value_->is_object()) Fail("expected an object");
  auto it = value_->find(key);
  if (it == value_->end()) Fail("missing field '" + key + "'");
  return JsonCursor(*it, source_, where_.empty() ? key : where_ + "." + key);
}

JsonCursor JsonCursor::At(size_t index) const {
  if (!value_->is_array()) Fail("expected an array");
  if (index >= value_->size()) {
    Fail("index " + std::to_string(index) + " out of range (size " +
         std::to_string(value_->size()) + ")");
  }
  return JsonCursor((*value_)[index], source_,
                    where_ + "[" + std::to_string(index) + "]");
}

size_t JsonCursor::ArraySize(long expected) const {
  if (!value_->is_array()) Fail("expected an array");
  if (expected >= 0 && value_->size() != static_cast<size_t>(expected)) {
    Fail("expected " + std::to_string(expected) + " elements, found " +
         std::to_string(value_->size()));
  }
  return value_->size();
}

double JsonCursor::Number() const {
  if (!value_->is_number()) Fail("expected a number");
  double v = value_->get<double>();
  if (!std::isfinite(v)) Fail("expected a finite number");
  return v;
}

double JsonCursor::NumberOrNan() const {
  if (value_->is_null()) return std::nan("");
  if (!value_->is_number()) Fail("expected a number or null");
  return value_->get<double>();
}

long JsonCursor::Integer() const {
  if (!value_->is_number_integer()) Fail("expected an integer");
  return value_->get<long>();
}

std::string JsonCursor::String() const {
  if (!value_->is_string()) Fail("expected a string");
  return value_->get<std::string>();
}

bool JsonCursor::Boolean() const {
  if (!value_->is_boolean()) Fail("expected true or false");
  return value_->get<bool>();
}

}  // namespace m2d
