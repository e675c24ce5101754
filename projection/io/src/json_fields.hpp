#pragma once
// Internal to facet's libraries: the one way facet reads its JSON files (display.json, rig files,
// capture.json, camera poses). Every error names the file, the field path and what was expected:
//
//   display.json: field 'projectors[2].blend': expected a string, got 3
//
// and Fields refuses members the reader does not know, so that a misspelled key is an error
// rather than a silently ignored setting:
//
//   display.json: field 'projectors[0].blnd': unknown field 'blnd'; did you mean 'blend'? (keys
//   starting with "x-" are free for notes)
//
// Not part of any public header: the JSON library stays an implementation detail.
#include <filesystem>
#include <glm/glm.hpp>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "facet/projection/base_projection.hpp"
#include "facet/projection/screen.hpp"

namespace facet::json_fields {

using Json = nlohmann::json;

// Where a value sits: the file (`source`) and the path to the value inside it, e.g.
// "projectors[1].output.window" ("" for the document itself).
class FieldPath {
 public:
  explicit FieldPath(std::string source, std::string field = "")
      : source_(std::move(source)), field_(std::move(field)) {}

  FieldPath operator[](std::string_view key) const;
  FieldPath operator[](std::size_t index) const;

  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }

  // Throws InputError(source, field, "expected " + expected).
  [[noreturn]] void fail(const std::string& expected) const;
  // Throws InputError(source, field, "expected " + expected + ", got " + short text of `got`).
  [[noreturn]] void fail(const std::string& expected, const Json& got) const;

 private:
  std::string source_, field_;
};

// A value as an error message quotes it: its JSON text, cut short after about 40 characters.
std::string quote_value(const Json& value);

// The members of one JSON object, read by name. Every name the reader asks for (found or not)
// and every name it allows counts as known; finish() refuses any other member whose key does not
// start with "x-", which stays free for users' own notes.
class Fields {
 public:
  // Fails with "expected a JSON object" unless `value` is one. `value` must outlive this.
  Fields(const Json& value, FieldPath at);

  const FieldPath& path() const { return at_; }
  FieldPath path(std::string_view key) const { return at_[key]; }

  // The member `key`, or nullptr when it is absent or null (null reads as "not given").
  const Json* optional(std::string_view key);
  // The member `key`, or nullptr when it is absent; a null value is returned as it is, so that the
  // reader's type check refuses it.
  const Json* present(std::string_view key);
  // The member `key`; fails with "expected EXPECTED (the field is missing)" when it is absent
  // and with "expected EXPECTED, got null" when it is null.
  const Json& required(std::string_view key, const std::string& expected);

  // Names this object may hold that the reader does not look at on this path (an alternative
  // that another member overrides): known, so not refused.
  void allow(std::initializer_list<std::string_view> keys);

  // Throws InputError naming the first unknown member (in document order) by its full path, with
  // the nearest known key when one is close ("unknown field 'blnd'; did you mean 'blend'?"), or
  // else the list of known keys.
  void finish() const;

 private:
  void know(std::string_view key);

  const Json& object_;
  FieldPath at_;
  std::vector<std::string> known_;
};

// The known key nearest to `key` by edit distance (insertions, deletions, substitutions and
// swaps of neighbours), or "" when none is within 2 edits, or within a third of the key's length
// for longer keys.
std::string nearest_key(std::string_view key, const std::vector<std::string>& known);

// Typed values; each fails at `at` with what it expected and what it got.
std::string to_string(const Json& value, const FieldPath& at);
double to_number(const Json& value, const FieldPath& at);  // finite
// An integer within ±1e9; 3.0 counts (JSON writers differ in how they print whole numbers).
int to_int(const Json& value, const FieldPath& at);
bool to_bool(const Json& value, const FieldPath& at);
// A list of `min_count` to `max_count` finite numbers; `expected` describes it.
std::vector<double> to_numbers(const Json& value, const FieldPath& at, std::size_t min_count,
                               std::size_t max_count, const std::string& expected);
glm::dvec2 to_dvec2(const Json& value, const FieldPath& at, const std::string& expected);
glm::dvec3 to_dvec3(const Json& value, const FieldPath& at);
glm::ivec2 to_ivec2(const Json& value, const FieldPath& at, const std::string& expected);
glm::ivec4 to_ivec4(const Json& value, const FieldPath& at, const std::string& expected);
// A matrix in JSON is a list of rows; glm stores columns.
glm::dmat3 to_dmat3(const Json& value, const FieldPath& at);

Json from_dvec3(const glm::dvec3& v);
Json from_dmat3(const glm::dmat3& m);

// A base projection's own parameters as every facet file stores them beside its kind:
// perspective "tan_extent" [left, right, top, bottom]; fisheye "fov" (degrees); cylindrical
// "azimuth" [s = 0, s = 1] (degrees) and "tan_elevation" [top, bottom]; equirectangular "azimuth"
// and "elevation" [top, bottom] (degrees). The kind's own key differs by file and stays the
// caller's.
void put_base_parameters(const BaseProjection& base, Json& object);
// The `kind` base whose parameters `object` holds, each failing at at[key]; not validated (the
// caller's BaseProjection::validate says what is out of its domain).
BaseProjection to_base_parameters(const Json& object, BaseKind kind, const FieldPath& at);

// The axes (columns right, down, forward) of a camera-like frame at `from` looking at `target`
// with `up` (any length) towards the image's top: what "look_at" and "up" members give. Fails at
// at["look_at"] ("a point other than the FROM_NAME itself") when target is `from`, and at at["up"]
// when up is parallel to the viewing direction.
glm::dmat3 look_at_axes(const glm::dvec3& from, const glm::dvec3& target, const glm::dvec3& up,
                        const FieldPath& at, const std::string& from_name);

// A screen surface, as display.json, rig files and capture.json all hold it:
//   {"type": "sphere", "center": [x, y, z], "radius": r}
//   {"type": "cylinder", "center": [x, y, z], "axis": [x, y, z], "radius": r}
//   {"type": "plane", "point": [x, y, z], "normal": [x, y, z]}
// in metres; the axis and normal any non-zero length (normalised on reading), the radius in
// (0, 1e6]. Unknown members are refused.
Screen to_screen(const Json& value, const FieldPath& at);
Json from_screen(const Screen& screen);
// A screen as a validate checks one built in code: finite, positions and the radius within
// 1,000 km, the radius positive, the axis (cylinder) and normal (plane) of unit length within
// 1e-6. Fails at `at` or the field at fault.
void check_screen(const Screen& screen, const FieldPath& at);

// Parses `text` as JSON; fails with "expected valid JSON (...)" at the document.
Json parse(const std::string& text, const std::string& source);
// Reads and parses a regular file (require_regular_file's checks first).
Json parse_file(const std::filesystem::path& path);

}  // namespace facet::json_fields
