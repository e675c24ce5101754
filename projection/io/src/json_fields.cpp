#include "json_fields.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"

namespace facet::json_fields {

FieldPath FieldPath::operator[](std::string_view key) const {
  return FieldPath(source_, field_.empty() ? std::string(key) : field_ + "." + std::string(key));
}

FieldPath FieldPath::operator[](std::size_t index) const {
  return FieldPath(source_, field_ + "[" + std::to_string(index) + "]");
}

void FieldPath::fail(const std::string& expected) const {
  throw InputError(source_, field_, "expected " + expected);
}

void FieldPath::fail(const std::string& expected, const Json& got) const {
  throw InputError(source_, field_, "expected " + expected + ", got " + quote_value(got));
}

std::string quote_value(const Json& value) {
  constexpr std::size_t kLongest = 40;
  std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
  if (text.size() > kLongest) text = text.substr(0, kLongest - 3) + "...";
  return text;
}

Fields::Fields(const Json& value, FieldPath at) : object_(value), at_(std::move(at)) {
  if (!object_.is_object()) at_.fail("a JSON object", object_);
}

void Fields::know(std::string_view key) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
}

const Json* Fields::present(std::string_view key) {
  know(key);
  const auto it = object_.find(key);
  return it == object_.end() ? nullptr : &*it;
}

const Json* Fields::optional(std::string_view key) {
  const Json* value = present(key);
  return value == nullptr || value->is_null() ? nullptr : value;
}

const Json& Fields::required(std::string_view key, const std::string& expected) {
  const Json* value = present(key);
  if (value == nullptr) at_[key].fail(expected + " (the field is missing)");
  if (value->is_null()) at_[key].fail(expected, *value);
  return *value;
}

void Fields::allow(std::initializer_list<std::string_view> keys) {
  for (const std::string_view key : keys) know(key);
}

void Fields::finish() const {
  for (const auto& [key, value] : object_.items()) {
    if (key.starts_with("x-")) continue;
    if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    const std::string free_note = "keys starting with \"x-\" are free for notes";
    std::string message = "unknown field '" + key + "'";
    if (const std::string nearest = nearest_key(key, known_); !nearest.empty()) {
      message += "; did you mean '" + nearest + "'? (" + free_note + ")";
    } else {
      std::vector<std::string> sorted = known_;
      std::sort(sorted.begin(), sorted.end());
      std::string list;
      for (const std::string& name : sorted) list += (list.empty() ? "" : ", ") + name;
      message += " (known here: " + list + "; " + free_note + ")";
    }
    throw InputError(at_.source(), at_[key].field(), message);
  }
}

namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring characters each cost 1.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[n][m];
}

}  // namespace

std::string nearest_key(std::string_view key, const std::vector<std::string>& known) {
  const std::size_t limit = std::max<std::size_t>(2, key.size() / 3);
  std::string best;
  std::size_t best_distance = limit + 1;
  for (const std::string& candidate : known) {
    const std::size_t distance = edit_distance(key, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  // Two edits turn any short key into another ("on" into "x"): suggest only a real resemblance.
  if (best_distance >= std::max(key.size(), best.size())) return "";
  return best;
}

std::string to_string(const Json& value, const FieldPath& at) {
  if (!value.is_string()) at.fail("a string", value);
  return value.get<std::string>();
}

double to_number(const Json& value, const FieldPath& at) {
  if (!value.is_number()) at.fail("a number", value);
  const double number = value.get<double>();
  if (!std::isfinite(number)) at.fail("a finite number", value);
  return number;
}

int to_int(const Json& value, const FieldPath& at) {
  if (value.is_number_integer()) {
    const auto number = value.get<long long>();
    if (value.is_number_unsigned() ? value.get<unsigned long long>() > 1'000'000'000ull
                                   : (number < -1'000'000'000 || number > 1'000'000'000)) {
      at.fail("an integer of sensible size (within ±1e9)", value);
    }
    return int(number);
  }
  if (value.is_number_float()) {
    const double number = value.get<double>();
    if (std::isfinite(number) && number == std::floor(number) && std::abs(number) <= 1e9) {
      return int(number);
    }
  }
  at.fail("an integer", value);
}

bool to_bool(const Json& value, const FieldPath& at) {
  if (!value.is_boolean()) at.fail("true or false", value);
  return value.get<bool>();
}

std::vector<double> to_numbers(const Json& value, const FieldPath& at, std::size_t min_count,
                               std::size_t max_count, const std::string& expected) {
  if (!value.is_array() || value.size() < min_count || value.size() > max_count) {
    at.fail(expected, value);
  }
  std::vector<double> numbers;
  numbers.reserve(value.size());
  for (std::size_t k = 0; k < value.size(); ++k) numbers.push_back(to_number(value[k], at[k]));
  return numbers;
}

glm::dvec2 to_dvec2(const Json& value, const FieldPath& at, const std::string& expected) {
  const std::vector<double> v = to_numbers(value, at, 2, 2, expected);
  return {v[0], v[1]};
}

glm::dvec3 to_dvec3(const Json& value, const FieldPath& at) {
  const std::vector<double> v = to_numbers(value, at, 3, 3, "a list of 3 numbers");
  return {v[0], v[1], v[2]};
}

glm::ivec2 to_ivec2(const Json& value, const FieldPath& at, const std::string& expected) {
  if (!value.is_array() || value.size() != 2) at.fail(expected, value);
  return {to_int(value[0], at[0]), to_int(value[1], at[1])};
}

glm::ivec4 to_ivec4(const Json& value, const FieldPath& at, const std::string& expected) {
  if (!value.is_array() || value.size() != 4) at.fail(expected, value);
  return {to_int(value[0], at[0]), to_int(value[1], at[1]), to_int(value[2], at[2]),
          to_int(value[3], at[3])};
}

glm::dmat3 to_dmat3(const Json& value, const FieldPath& at) {
  if (!value.is_array() || value.size() != 3) at.fail("a 3x3 matrix as a list of 3 rows", value);
  glm::dmat3 matrix(0.0);
  for (std::size_t row = 0; row < 3; ++row) {
    const glm::dvec3 values = to_dvec3(value[row], at[row]);
    for (int column = 0; column < 3; ++column) matrix[column][int(row)] = values[column];
  }
  return matrix;
}

Json from_dvec3(const glm::dvec3& v) { return Json::array({v.x, v.y, v.z}); }

Json from_dmat3(const glm::dmat3& m) {
  Json rows = Json::array();
  for (int row = 0; row < 3; ++row) rows.push_back({m[0][row], m[1][row], m[2][row]});
  return rows;
}

void put_base_parameters(const BaseProjection& base, Json& object) {
  switch (base.kind) {
    case BaseKind::perspective:
      object["tan_extent"] = base.tan_extent;
      break;
    case BaseKind::fisheye:
      object["fov"] = base.fov_deg;
      break;
    case BaseKind::cylindrical:
      object["azimuth"] = base.azimuth_deg;
      object["tan_elevation"] = base.tan_elevation;
      break;
    case BaseKind::equirectangular:
      object["azimuth"] = base.azimuth_deg;
      object["elevation"] = base.elevation_deg;
      break;
  }
}

BaseProjection to_base_parameters(const Json& object, BaseKind kind, const FieldPath& at) {
  const auto member = [&](const char* key, const std::string& expected) -> const Json& {
    if (!object.is_object()) at.fail("a JSON object", object);
    const auto it = object.find(key);
    if (it == object.end()) at[key].fail(expected + " (the field is missing)");
    return *it;
  };
  const auto pair = [&](const char* key, const std::string& expected) {
    const std::vector<double> v = to_numbers(member(key, expected), at[key], 2, 2, expected);
    return std::array<double, 2>{v[0], v[1]};
  };
  BaseProjection base;
  base.kind = kind;
  switch (kind) {
    case BaseKind::perspective: {
      const std::string expected = "a list of 4 tangents [left, right, top, bottom]";
      const std::vector<double> v =
          to_numbers(member("tan_extent", expected), at["tan_extent"], 4, 4, expected);
      base.tan_extent = {v[0], v[1], v[2], v[3]};
      break;
    }
    case BaseKind::fisheye:
      base.fov_deg = to_number(member("fov", "a number of degrees"), at["fov"]);
      break;
    case BaseKind::cylindrical:
      base.azimuth_deg = pair("azimuth", "a list of 2 azimuths in degrees");
      base.tan_elevation = pair("tan_elevation", "a list of 2 tangents [top, bottom]");
      break;
    case BaseKind::equirectangular:
      base.azimuth_deg = pair("azimuth", "a list of 2 azimuths in degrees");
      base.elevation_deg = pair("elevation", "a list of 2 elevations in degrees [top, bottom]");
      break;
  }
  return base;
}

glm::dmat3 look_at_axes(const glm::dvec3& from, const glm::dvec3& target, const glm::dvec3& up,
                        const FieldPath& at, const std::string& from_name) {
  const glm::dvec3 forward_raw = target - from;
  if (!(glm::length(forward_raw) > 1e-9)) {
    at["look_at"].fail("a point other than the " + from_name + " itself");
  }
  const glm::dvec3 forward = glm::normalize(forward_raw);
  const glm::dvec3 right_raw = glm::cross(forward, up);
  if (!(glm::length(right_raw) > 1e-9 * std::max(1.0, glm::length(up)))) {
    at["up"].fail("an up vector that is not parallel to the viewing direction");
  }
  const glm::dvec3 right = glm::normalize(right_raw);
  return glm::dmat3(right, glm::cross(forward, right), forward);
}

Screen to_screen(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  const std::string expected_type = "\"sphere\", \"cylinder\" or \"plane\"";
  const std::string type = to_string(fields.required("type", expected_type), at["type"]);
  auto point = [&](const char* key) {
    return to_dvec3(fields.required(key, "a point in metres"), at[key]);
  };
  auto unit = [&](const char* key) {
    const glm::dvec3 v = to_dvec3(fields.required(key, "a list of 3 numbers"), at[key]);
    if (!(glm::length(v) > 1e-12)) at[key].fail("a non-zero vector");
    return glm::normalize(v);
  };
  auto radius = [&] {
    const std::string expected = "a positive number of metres, at most 1,000 km (1e6 m)";
    const double r = to_number(fields.required("radius", expected), at["radius"]);
    if (!(r > 0 && r <= 1e6)) at["radius"].fail(expected, r);
    return r;
  };
  Screen screen;
  if (type == "sphere") {
    screen.type = Screen::Type::sphere;
    screen.center = point("center");
    screen.radius = radius();
  } else if (type == "cylinder") {
    screen.type = Screen::Type::cylinder;
    screen.center = point("center");
    screen.axis = unit("axis");
    screen.radius = radius();
  } else if (type == "plane") {
    screen.type = Screen::Type::plane;
    screen.point = point("point");
    screen.normal = unit("normal");
  } else {
    at["type"].fail(expected_type, type);
  }
  fields.finish();
  return screen;
}

Json from_screen(const Screen& screen) {
  switch (screen.type) {
    case Screen::Type::sphere:
      return {{"type", "sphere"}, {"center", from_dvec3(screen.center)}, {"radius", screen.radius}};
    case Screen::Type::cylinder:
      return {{"type", "cylinder"},
              {"center", from_dvec3(screen.center)},
              {"axis", from_dvec3(screen.axis)},
              {"radius", screen.radius}};
    case Screen::Type::plane:
      return {{"type", "plane"},
              {"point", from_dvec3(screen.point)},
              {"normal", from_dvec3(screen.normal)}};
  }
  return {};
}

void check_screen(const Screen& screen, const FieldPath& at) {
  constexpr double kMaxDistance_m = 1e6;
  auto finite = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  auto within_reach = [&](const glm::dvec3& p_m) {
    return finite(p_m) && std::abs(p_m.x) <= kMaxDistance_m && std::abs(p_m.y) <= kMaxDistance_m &&
           std::abs(p_m.z) <= kMaxDistance_m;
  };
  auto is_unit = [](const glm::dvec3& v) { return std::abs(glm::length(v) - 1.0) <= 1e-6; };
  if (!within_reach(screen.center) || !within_reach(screen.point) || !finite(screen.axis) ||
      !finite(screen.normal)) {
    at.fail("finite numbers, positions each within ±1,000 km (1e6 m)");
  }
  if (screen.type != Screen::Type::plane &&
      !(screen.radius > 0 && screen.radius <= kMaxDistance_m)) {
    at["radius"].fail("a positive number of metres, at most 1,000 km (1e6 m)");
  }
  if (screen.type == Screen::Type::cylinder && !is_unit(screen.axis)) {
    at["axis"].fail("a unit vector");
  }
  if (screen.type == Screen::Type::plane && !is_unit(screen.normal)) {
    at["normal"].fail("a unit vector");
  }
}

// Deeper nesting is refused while parsing: no facet document comes near it, and walking such a
// document recursively (dumping a value into an error message) would overflow the stack.
constexpr int kMaxJsonDepth = 256;

Json parse(const std::string& text, const std::string& source) {
  try {
    return Json::parse(text, [&](int depth, Json::parse_event_t, Json&) {
      if (depth > kMaxJsonDepth) {
        FieldPath(source).fail("JSON nested at most " + std::to_string(kMaxJsonDepth) +
                               " levels deep");
      }
      return true;
    });
  } catch (const Json::exception& error) {  // a syntax error, or a number beyond double's range
    FieldPath(source).fail(std::string("valid JSON (") + error.what() + ")");
  }
}

Json parse_file(const std::filesystem::path& path) {
  require_regular_file(path);
  std::ifstream stream(path, std::ios::binary);
  if (!stream) FieldPath(path.string()).fail("a readable file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return parse(buffer.str(), path.string());
}

}  // namespace facet::json_fields
