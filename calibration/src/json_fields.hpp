#pragma once
// Internal: typed access to JSON members that throws InputError naming the file and the field.
#include <cmath>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet::calibration::detail {

struct JsonContext {
  std::string source;  // the file
  std::string field;   // path of the object, e.g. "projectors[0]"

  std::string member(const std::string& key) const {
    return field.empty() ? key : field + "." + key;
  }
  std::string element(std::size_t index) const { return field + "[" + std::to_string(index) + "]"; }
  JsonContext at(const std::string& key) const { return {source, member(key)}; }
  JsonContext at(std::size_t index) const { return {source, element(index)}; }
  [[noreturn]] void fail(const std::string& expected) const {
    throw InputError(source, field, expected);
  }
};

inline const nlohmann::json& require_object(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_object()) at.fail("a JSON object");
  return value;
}

inline const nlohmann::json* find_member(const nlohmann::json& object, const std::string& key) {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

inline const nlohmann::json& require_member(const nlohmann::json& object, const std::string& key,
                                            const JsonContext& at, const std::string& expected) {
  const nlohmann::json* value = find_member(object, key);
  if (value == nullptr) at.at(key).fail(expected + " (the field is missing)");
  return *value;
}

inline std::string to_string(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_string()) at.fail("a string");
  return value.get<std::string>();
}

inline double to_number(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_number()) at.fail("a number");
  const double number = value.get<double>();
  if (!std::isfinite(number)) at.fail("a finite number");
  return number;
}

inline int to_int(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_number_integer()) {
    // Accept 3.0 but not 3.5: JSON writers differ in how they print whole numbers.
    if (value.is_number_float()) {
      const double number = value.get<double>();
      if (std::isfinite(number) && number == std::floor(number) && std::abs(number) < 1e9) {
        return int(number);
      }
    }
    at.fail("an integer");
  }
  const auto number = value.get<long long>();
  if (number < -1'000'000'000 || number > 1'000'000'000) at.fail("an integer of sensible size");
  return int(number);
}

inline bool to_bool(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_boolean()) at.fail("true or false");
  return value.get<bool>();
}

inline glm::dvec3 to_dvec3(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_array() || value.size() != 3) at.fail("a list of 3 numbers");
  return {to_number(value[0], at.at(0)), to_number(value[1], at.at(1)),
          to_number(value[2], at.at(2))};
}

// A matrix in JSON is a list of rows; glm stores columns.
inline glm::dmat3 to_dmat3(const nlohmann::json& value, const JsonContext& at) {
  if (!value.is_array() || value.size() != 3) at.fail("a 3x3 matrix as a list of 3 rows");
  glm::dmat3 matrix(0.0);
  for (std::size_t row = 0; row < 3; ++row) {
    const glm::dvec3 values = to_dvec3(value[row], at.at(row));
    for (int col = 0; col < 3; ++col) matrix[col][int(row)] = values[col];
  }
  return matrix;
}

inline nlohmann::json from_dvec3(const glm::dvec3& v) {
  return nlohmann::json::array({v.x, v.y, v.z});
}

inline nlohmann::json from_dmat3(const glm::dmat3& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int row = 0; row < 3; ++row) rows.push_back({m[0][row], m[1][row], m[2][row]});
  return rows;
}

}  // namespace facet::calibration::detail
