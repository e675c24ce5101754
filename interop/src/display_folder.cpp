#include "facet/interop/display_folder.hpp"

#include <fstream>
#include <set>

#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::interop {
namespace {

// The imports and exports write a new or empty --out folder.
OutputFolderRules out_folder_rules() {
  OutputFolderRules rules;
  rules.field = OptionName{"out"};
  rules.expected = "expected a folder that does not exist or is empty";
  return rules;
}

}  // namespace

void check_out_folder(const std::filesystem::path& folder) {
  check_output_folder(folder, out_folder_rules());
}

std::string sanitize_name(const std::string& text) {
  std::string name;
  for (char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    name += ok ? c : '_';
  }
  return name.empty() ? "projector" : name;
}

void write_display_folder(const ImportedDisplay& display, const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  projection_io::DisplayConfig config;
  config.name = display.name.empty() ? "imported" : display.name;
  config.missing_monitor = projection_io::MissingMonitor::window;
  config.eye = display.eye;
  std::set<std::string> names;
  for (const ImportedProjector& projector : display.projectors) {
    std::string name = sanitize_name(projector.name);
    for (int n = 2; names.count(name); ++n)
      name = sanitize_name(projector.name) + "-" + std::to_string(n);
    names.insert(name);
    projection_io::DisplayProjector entry;
    entry.name = name;
    entry.size = projector.warp.output_size;
    entry.warp = name + ".warp.exr";
    if (projector.blend) entry.blend = name + ".blend.exr";
    if (projector.black) entry.black = name + ".black.exr";
    entry.output = projector.output;
    config.projectors.push_back(entry);
  }
  if (display.cluster) {
    // The nodes name projectors as the importer did; the names written may differ.
    config.cluster = *display.cluster;
    for (projection_io::ClusterNode& node : config.cluster->nodes) {
      for (std::string& name : node.projectors) {
        for (std::size_t p = 0; p < display.projectors.size(); ++p) {
          if (display.projectors[p].name == name) {
            name = config.projectors[p].name;
            break;
          }
        }
      }
    }
  }
  projection_io::validate_display_config(config, folder.string() + "/display.json", false);

  write_folder_atomically(
      folder,
      [&](const fs::path& temporary) {
        for (std::size_t p = 0; p < display.projectors.size(); ++p) {
          const ImportedProjector& projector = display.projectors[p];
          const projection_io::DisplayProjector& entry = config.projectors[p];
          write_warp((temporary / entry.warp).string(), projector.warp);
          if (projector.blend)
            projection_io::write_blend_map((temporary / *entry.blend).string(), *projector.blend);
          if (projector.black)
            projection_io::write_blend_map((temporary / *entry.black).string(), *projector.black);
        }
        projection_io::write_display_config(config, temporary / "display.json");
      },
      out_folder_rules());
}

void write_files_folder(const std::map<std::string, std::string>& files,
                        const std::filesystem::path& folder) {
  write_folder_atomically(
      folder,
      [&](const std::filesystem::path& temporary) {
        for (const auto& [name, bytes] : files) {
          std::ofstream out(temporary / name, std::ios::binary);
          out << bytes;
          if (!out.flush()) {
            throw InputError((folder / name).string(), "", "cannot write the file");
          }
        }
      },
      out_folder_rules());
}

}  // namespace facet::interop
