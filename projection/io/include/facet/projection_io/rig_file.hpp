#pragma once
// The virtual rig's JSON file, "facet-rig/1" (configs/rigs/README.md documents every field).
#include <filesystem>
#include <string>
#include <vector>

#include "facet/projection/rig.hpp"

namespace facet {

inline constexpr const char* kRigFormat = "facet-rig/1";

// Parses and validates a rig; `source` names the file in errors. Poses are given either as a
// rotation matrix (R_eye_projector, R_eye_camera) or as a point to look at with an optional up
// vector; either way the rig holds the rotation. Throws InputError(source, field, expected) with
// fields such as "projectors[2].look_at" on the first problem, unknown fields included (keys
// starting with "x-" are free for notes).
Rig parse_rig(const std::string& text, const std::string& source);
// Reads and parses a rig file (InputError when it cannot be read).
Rig read_rig(const std::filesystem::path& path);

// The rigs of configs/rigs, compiled into the library (their file names without ".json").
std::vector<std::string> builtin_rig_names();
// "builtin:NAME", one of builtin_rig_names(), from any folder; anything else is a rig file's path
// (read_rig). InputError for an unknown built-in name, listing the known ones.
Rig load_rig(const std::string& name_or_path);

// The rig as JSON text, in full precision, with rotations as matrices; parse_rig reads back an
// equal Rig.
std::string format_rig(const Rig& rig);
// Validates, then writes atomically.
void write_rig(const std::filesystem::path& path, const Rig& rig);

}  // namespace facet
