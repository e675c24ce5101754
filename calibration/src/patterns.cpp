#include "facet/calibration/patterns.hpp"

#include <cmath>
#include <fstream>
#include <numbers>

#include "facet/calibration/image_io.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "json_fields.hpp"

namespace facet::calibration {

int gray_bits(int size) {
  FACET_ASSERT(size >= 1);
  int bits = 0;
  while ((1LL << bits) < size) ++bits;
  return bits;
}

double pattern_value(const Pattern& pattern, int c, int r) {
  switch (pattern.type) {
    case PatternType::white:
      return 1.0;
    case PatternType::black:
      return 0.0;
    case PatternType::gray: {
      FACET_ASSERT(pattern.bit >= 0 && pattern.bit < 31);
      const unsigned index = unsigned(pattern.axis == Axis::x ? c : r);
      const unsigned gray = index ^ (index >> 1);
      const bool set = ((gray >> pattern.bit) & 1u) != 0;
      return set != pattern.inverted ? 1.0 : 0.0;
    }
    case PatternType::phase: {
      FACET_ASSERT(pattern.period > 0 && pattern.steps >= 1);
      const double index = pattern.axis == Axis::x ? c : r;
      return 0.5 + 0.5 * std::cos(2 * std::numbers::pi * (index + 0.5) / pattern.period -
                                  2 * std::numbers::pi * pattern.step / pattern.steps);
    }
  }
  FACET_ASSERT(false);
}

cv::Mat render_pattern(const Pattern& pattern, glm::ivec2 projector_size) {
  FACET_ASSERT(projector_size.x >= 1 && projector_size.y >= 1);
  cv::Mat image(projector_size.y, projector_size.x, CV_32F);
  // Patterns vary along one axis only: compute one row or column and replicate it.
  if (pattern.axis == Axis::x || pattern.type == PatternType::white ||
      pattern.type == PatternType::black) {
    auto* first = image.ptr<float>(0);
    for (int c = 0; c < projector_size.x; ++c) first[c] = float(pattern_value(pattern, c, 0));
    for (int r = 1; r < projector_size.y; ++r) image.row(0).copyTo(image.row(r));
  } else {
    for (int r = 0; r < projector_size.y; ++r) {
      image.row(r).setTo(float(pattern_value(pattern, 0, r)));
    }
  }
  return image;
}

std::vector<Pattern> standard_patterns(glm::ivec2 size, const PatternSetOptions& options) {
  FACET_ASSERT(size.x >= 1 && size.y >= 1);
  std::vector<Pattern> patterns{Pattern::white(), Pattern::black()};
  for (Axis axis : {Axis::x, Axis::y}) {
    for (int bit = gray_bits(axis == Axis::x ? size.x : size.y) - 1; bit >= 0; --bit) {
      patterns.push_back(Pattern::gray(axis, bit));
      patterns.push_back(Pattern::gray(axis, bit, true));
    }
  }
  if (options.phase_period) {
    FACET_ASSERT(*options.phase_period > 0 && options.phase_steps >= 3);
    for (Axis axis : {Axis::x, Axis::y}) {
      for (int step = 0; step < options.phase_steps; ++step) {
        patterns.push_back(Pattern::phase(axis, *options.phase_period, step, options.phase_steps));
      }
    }
  }
  return patterns;
}

std::string default_file_name(const Pattern& pattern, const std::string& extension) {
  const std::string axis = pattern.axis == Axis::x ? "x" : "y";
  switch (pattern.type) {
    case PatternType::white:
      return "white" + extension;
    case PatternType::black:
      return "black" + extension;
    case PatternType::gray:
      return "g" + axis + std::to_string(pattern.bit) + (pattern.inverted ? "i" : "") + extension;
    case PatternType::phase:
      return "p" + axis + std::to_string(pattern.step) + extension;
  }
  FACET_ASSERT(false);
}

nlohmann::json pattern_to_json(const Pattern& pattern) {
  const std::string axis = pattern.axis == Axis::x ? "x" : "y";
  switch (pattern.type) {
    case PatternType::white:
      return {{"type", "white"}};
    case PatternType::black:
      return {{"type", "black"}};
    case PatternType::gray: {
      nlohmann::json object{{"type", "gray"}, {"axis", axis}, {"bit", pattern.bit}};
      if (pattern.inverted) object["inverted"] = true;
      return object;
    }
    case PatternType::phase:
      return {{"type", "phase"},
              {"axis", axis},
              {"period", pattern.period},
              {"step", pattern.step},
              {"steps", pattern.steps}};
  }
  FACET_ASSERT(false);
}

Pattern pattern_from_json(const nlohmann::json& object, const std::string& source,
                          const std::string& field) {
  using namespace json_fields;
  const FieldPath at(source, field);
  Fields fields(object, at);
  const std::string expected_type = "\"white\", \"black\", \"gray\" or \"phase\"";
  const std::string type = to_string(fields.required("type", expected_type), at["type"]);
  auto read_axis = [&] {
    const Json& value = fields.required("axis", "\"x\" or \"y\"");
    const std::string axis = to_string(value, at["axis"]);
    if (axis == "x") return Axis::x;
    if (axis == "y") return Axis::y;
    at["axis"].fail("\"x\" or \"y\"", value);
  };
  Pattern pattern;
  if (type == "white") {
    pattern.type = PatternType::white;
  } else if (type == "black") {
    pattern.type = PatternType::black;
  } else if (type == "gray") {
    pattern.type = PatternType::gray;
    pattern.axis = read_axis();
    pattern.bit = to_int(fields.required("bit", "an integer from 0"), at["bit"]);
    if (pattern.bit < 0 || pattern.bit > 30) at["bit"].fail("an integer from 0 to 30", pattern.bit);
    if (const Json* inverted = fields.present("inverted")) {
      pattern.inverted = to_bool(*inverted, at["inverted"]);
    }
  } else if (type == "phase") {
    pattern.type = PatternType::phase;
    pattern.axis = read_axis();
    pattern.period =
        to_number(fields.required("period", "a positive number of pixels"), at["period"]);
    if (!(pattern.period > 0)) at["period"].fail("a positive number of pixels", pattern.period);
    pattern.steps = to_int(fields.required("steps", "an integer >= 3"), at["steps"]);
    if (pattern.steps < 3) at["steps"].fail("an integer >= 3", pattern.steps);
    pattern.step = to_int(fields.required("step", "an integer from 0 to steps-1"), at["step"]);
    if (pattern.step < 0 || pattern.step >= pattern.steps) {
      at["step"].fail("an integer from 0 to steps-1 = " + std::to_string(pattern.steps - 1),
                      pattern.step);
    }
  } else {
    at["type"].fail(expected_type, type);
  }
  fields.finish();
  return pattern;
}

void write_pattern_folder(const std::filesystem::path& out_dir, glm::ivec2 size,
                          const std::vector<Pattern>& patterns, int bit_depth) {
  FACET_ASSERT(size.x >= 1 && size.y >= 1);
  FACET_ASSERT(bit_depth == 8 || bit_depth == 16);
  // Checked first naming the flag, and again when written.
  OutputFolderRules out_rules;
  out_rules.field = OptionName{"out"};
  check_output_folder(out_dir, out_rules);
  write_folder_atomically(out_dir, [&](const std::filesystem::path& folder) {
    nlohmann::json frames = nlohmann::json::array();
    for (const Pattern& pattern : patterns) {
      const std::string file = default_file_name(pattern);
      write_grey_image(folder / file, render_pattern(pattern, size), bit_depth);
      frames.push_back({{"file", file}, {"pattern", pattern_to_json(pattern)}});
    }
    const nlohmann::json manifest{{"format", "facet-patterns/1"},
                                  {"size", {size.x, size.y}},
                                  {"bit_depth", bit_depth},
                                  {"frames", frames}};
    std::ofstream stream(folder / "manifest.json");
    stream << manifest.dump(1) << "\n";
    if (!stream) throw InputError((out_dir / "manifest.json").string(), "", "a writable file");
  });
}

}  // namespace facet::calibration
