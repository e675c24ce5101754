#pragma once
// Structured-light patterns (FORMATS.md §1): white, black, Gray code with inverses, and phase
// shifting. Pattern values are in [0,1] *before* the projector's gamma: a value v emits light
// proportional to v^gamma.
#include <filesystem>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace facet::calibration {

enum class PatternType { white, black, gray, phase };
enum class Axis { x, y };  // x: projector columns c, y: projector rows r

struct Pattern {
  PatternType type = PatternType::white;
  Axis axis = Axis::x;    // gray and phase
  int bit = 0;            // gray: bit b of g = c XOR (c >> 1), bit 0 least significant
  bool inverted = false;  // gray: the complement
  double period = 0;      // phase: projector pixels per cycle, > 0
  int step = 0;           // phase: 0 <= step < steps
  int steps = 0;          // phase: number of shifts, >= 3

  bool operator==(const Pattern&) const = default;

  static Pattern white() { return {}; }
  static Pattern black() { return {.type = PatternType::black}; }
  static Pattern gray(Axis axis, int bit, bool inverted = false) {
    return {.type = PatternType::gray, .axis = axis, .bit = bit, .inverted = inverted};
  }
  static Pattern phase(Axis axis, double period, int step, int steps) {
    return {
        .type = PatternType::phase, .axis = axis, .period = period, .step = step, .steps = steps};
  }
};

// Number of Gray bits that identify every pixel of an axis of `size` pixels: ceil(log2(size)),
// 0 for size 1. Asserts size >= 1.
int gray_bits(int size);

// The pattern's value at projector pixel (c, r), integers from 0, in [0,1] before gamma. The value
// is constant over the pixel; phase is evaluated at the pixel centre c + 0.5.
double pattern_value(const Pattern& pattern, int c, int r);

// The whole pattern image, projector_size = (W, H), CV_32F, values in [0,1] before gamma.
cv::Mat render_pattern(const Pattern& pattern, glm::ivec2 projector_size);

struct PatternSetOptions {
  std::optional<double> phase_period;  // projector pixels; no phase frames when unset
  int phase_steps = 4;                 // >= 3
};

// The standard sequence for a projector of `size` (W, H): white, black, then for x then y every
// Gray bit from the most significant down, each followed by its inverse, then the phase steps of
// x then y when a period is given.
std::vector<Pattern> standard_patterns(glm::ivec2 size, const PatternSetOptions& options = {});

// A short file name, e.g. "white.png", "gx9.png", "gx9i.png", "py2.png" (phase step 2 of y).
std::string default_file_name(const Pattern& pattern, const std::string& extension = ".png");

// The JSON pattern object of capture.json's frames (FORMATS.md §1). `inverted` is written only
// when true.
nlohmann::json pattern_to_json(const Pattern& pattern);
// Parses and checks one pattern object; throws InputError(source, field, expected) naming the
// bad member as `field + "." + member`. Does not check `bit` against a projector size.
Pattern pattern_from_json(const nlohmann::json& object, const std::string& source,
                          const std::string& field);

// Writes the images of `patterns` for a projector of `size` into the folder `out_dir`
// (bit_depth 8 or 16, PNG, values rounded to the nearest level) plus `manifest.json`:
// {"format": "facet-patterns/1", "size": [W, H], "frames": [{"file", "pattern"}, ...]}.
// The folder appears whole or not at all. Throws InputError when out_dir exists and is not an
// empty folder.
void write_pattern_folder(const std::filesystem::path& out_dir, glm::ivec2 size,
                          const std::vector<Pattern>& patterns, int bit_depth = 8);

}  // namespace facet::calibration
