#pragma once
// Test patterns for aligning projectors on the real screen (`facet run --pattern`): images drawn
// per projector output from its warp, with no scene.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet {

enum class TestPattern {
  // Output-space lines every 32 px (every 128 px brighter), the border and the centre cross:
  // shows the raster itself, keystone and edges.
  grid,
  // Latitude and longitude every 10° in the eye's frame (every 30° brighter; the horizon green,
  // the front meridian red), through the exact warp: neighbours line up where the lines meet.
  latlong,
  // The projector's colour (as in `facet preview`) with its name and index large in the middle.
  projector_ids,
  white,
  black,
  // 64-px output-space checkerboard.
  checker,
};

// "grid", "latlong", "projector-ids", "white", "black", "checker".
std::string to_string(TestPattern pattern);
// InputError(source, field, ...) for any other name.
TestPattern test_pattern_from_string(const std::string& name, const std::string& source,
                                     const std::string& field);
// Every pattern, in the order a windowed session's key cycles through them.
const std::vector<TestPattern>& all_test_patterns();

// Whether the output's blend and black level apply to the pattern as they do to a scene: latlong,
// white and black (so overlaps sum as the audience sees them); grid, checker and projector IDs
// are each projector's raw raster.
bool test_pattern_is_blended(TestPattern pattern);

// The pattern for projector `index` (named `name`) showing `warp`: sRGB RGBA8, the warp's output
// size, row 0 at the top. latlong inverts the warp at every pixel (WarpInverse); pixels no base
// point maps to are black.
std::vector<std::uint8_t> test_pattern_image(TestPattern pattern, const Warp& warp,
                                             std::size_t index, const std::string& name);

}  // namespace facet
