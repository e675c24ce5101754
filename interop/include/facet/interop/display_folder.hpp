#pragma once
// Writing an imported display: a folder holding display.json (FORMATS.md §4) with one
// `.warp.exr` per projector and its optional blend and black-level maps.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/warp.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::interop {

struct ImportedProjector {
  std::string name;  // a display.json projector name: letters, digits, '_', '-', '.'
  Warp warp;
  std::optional<projection_io::BlendMap> blend;  // α at the output size
  std::optional<projection_io::BlendMap> black;  // β at the output size
  projection_io::DisplayOutput output;           // where the image goes
  std::vector<std::string> notes;                // what the importer changed or guessed
};

struct ImportedDisplay {
  std::string name;
  std::vector<ImportedProjector> projectors;
  glm::dvec3 eye{0.0};  // display.json `eye`: world frame (facet's eye axes), metres
  // What an importer wants the user to know (a guessed eye point, masked folds): one sentence
  // each, for the CLI to print.
  std::vector<std::string> notes;
  // The render nodes the display came from (an SGCT cluster's), their projectors named as in
  // `projectors`: written as display.json's cluster section.
  std::optional<projection_io::DisplayCluster> cluster;
};

// Turns any text into a projector name display.json accepts ("" becomes "projector").
std::string sanitize_name(const std::string& text);

// Writes DIR/display.json, DIR/<name>.warp.exr and, where present, DIR/<name>.blend.exr and
// DIR/<name>.black.exr. Everything is written into a temporary folder next to `folder`, which is
// renamed onto `folder` only when complete, so a failure leaves nothing behind. `folder` must not
// exist or be empty (InputError naming it otherwise).
void write_display_folder(const ImportedDisplay& display, const std::filesystem::path& folder);

// The checks write_display_folder and write_files_folder make of `folder` (the --out flag) before
// writing, for a command to make before its work: InputError naming it and --out.
void check_out_folder(const std::filesystem::path& folder);

// Writes files given as name → bytes the same way into `folder`.
void write_files_folder(const std::map<std::string, std::string>& files,
                        const std::filesystem::path& folder);

}  // namespace facet::interop
