#pragma once
// SGCT cluster configurations (XML) whose viewports carry SCISS `.sgc` or SimCAD `.simcad`
// correction meshes and soft-edge masks, as dome installations ship them:
//
//   <Cluster> <Node> <Window> <Pos x y/>? <Size x y/>
//     <Viewport name mesh="channel1.sgc" mask="channel1.png"> <Pos x y/>? <Size x y/>? ...
//   ... <User> <Pos x y z/> </User>
//
// Every viewport with a mesh becomes a projector: its output is the viewport's part of its
// window (viewport Pos and Size are fractions of the window, default the whole window), and the
// mesh's own frustum and rotation (sgc.hpp) give the warp; a `.simcad` file holds none, so its
// viewport's <PlanarProjection> (FOV, Orientation) gives them. SimCAD's cluster files name no
// meshes: viewports with a <PlanarProjection> and no mesh attribute take the `.simcad` files in
// the configuration's folder, each the one whose `<stem>_frustum.csv` holds the viewport's FOV and
// heading, pitch, roll within 0.001° where every file has that table, else in order (the k-th such
// viewport, the k-th file by name) when the counts agree; notes say which file each took. Once one
// such viewport has found its file, one that finds none is an InputError naming it. The mask is an
// image over the output that SGCT multiplies into the encoded colour, so the linear blend weight is
// mask^gamma. Viewports without a mesh (an operator's GUI window) are left out with a note. Each
// node is its own machine; the import places the nodes' windows left to right on one desktop.
//
// Mesh and mask paths are often absolute paths of the machine that wrote the file; a path that
// does not exist is looked up by its file name in the configuration's folder, with a note.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "facet/interop/display_folder.hpp"
#include "facet/interop/sgc.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::interop {

struct SgctImportOptions {
  double mask_gamma = 2.2;     // linear α = mask^gamma
  glm::ivec2 warp_grid{0, 0};  // as SgcImportOptions
};

// Throws InputError naming the file and the element or attribute: not XML, no <Cluster>, a
// window without a positive <Size>, viewport fractions outside [0,1], a mesh that is not a
// `.sgc` or `.simcad` file or cannot be found, a `.simcad` mesh without a <PlanarProjection>, no
// viewport with a mesh, and every error of parse_sgc, parse_simcad and import_sgc.
ImportedDisplay import_sgct_cluster(const std::filesystem::path& config,
                                    const SgctImportOptions& options);

// Bare `.sgc` meshes, one projector each at `output_size`, named by file stem and placed left to
// right. Throws InputError naming a file that cannot be read, does not parse or import, or
// shares another's name.
ImportedDisplay import_sgc_files(const std::vector<std::filesystem::path>& meshes,
                                 glm::ivec2 output_size, glm::ivec2 warp_grid = {0, 0});

struct SgctExportOptions {
  double node_spacing_px = 4;  // between mesh vertices, output px, in [1, 1024]
  double mask_gamma = 2.2;     // the mask holds α^(1/gamma), 8 bits
};

// A display as SGCT reads it: file name → bytes, "cluster.xml" (one node per projector, each on
// 127.0.0.1 with its own port, a fullscreen window of the projector's size holding one
// viewport), "<projector>.sgc" and "<projector>_mask.png". Each mesh is a version-1 SCISS grid
// regular over the output with vertices every `node_spacing_px`, its frustum the perspective one
// that holds what the projector shows (covering_frustum, as the MPCDI export); a vertex the warp
// does not cover continues the warp's map (or, beyond its reach, its neighbours), and the mask,
// the blend weight where the warp covers a pixel centre and 0 elsewhere, hides it. Throws
// InputError naming the warp file for a footprint no frustum holds.
std::map<std::string, std::string> export_sgct(const projection_io::DisplayConfig& display,
                                               const SgctExportOptions& options);

}  // namespace facet::interop
