#pragma once
// The GLC camera file, "facet-glc/1" (*.glc.json; driver/README.md, "GLC cameras", documents
// every field): a multi-perspective camera that `facet render --method glc` renders into one
// output.
#include <filesystem>
#include <string>

#include "facet/projection/glc.hpp"

namespace facet {

inline constexpr const char* kGlcFormat = "facet-glc/1";

// Parses and validates a GLC camera; `source` names the file in errors. Throws
// InputError(source, field, expected) on the first problem with fields such as
// "camera.generators[1].direction" or "camera.size" (sizes beyond check_glc_size's limits are
// refused before anything is built), unknown fields included (keys starting with "x-" are free
// for notes).
PiecewiseGlc parse_glc_camera(const std::string& text, const std::string& source);
// Reads and parses a GLC camera file (InputError when it cannot be read).
PiecewiseGlc read_glc_camera(const std::filesystem::path& path);

}  // namespace facet
