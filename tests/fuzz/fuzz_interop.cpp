// Fuzz entry points of interop's readers: PFM, MPCDI containers, Paul Bourke meshes, SCISS .sgc
// and SimCAD meshes, and SGCT cluster files.
#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "facet/interop/bourke.hpp"
#include "facet/interop/mpcdi.hpp"
#include "facet/interop/pfm.hpp"
#include "facet/interop/sgc.hpp"
#include "facet/interop/sgct_cluster.hpp"
#include "facet/projection/errors.hpp"
#include "fuzz_target.hpp"

namespace {
using facet::fuzz::text_of;
using facet::fuzz::write_scratch;
}  // namespace

// A parsed file must format back to bytes that parse to the same image.
FACET_FUZZ_TARGET(pfm) {
  try {
    const auto image = facet::interop::parse_pfm(text_of(bytes), "fuzz.pfm");
    const auto again = facet::interop::parse_pfm(facet::interop::format_pfm(image), "again.pfm");
    if (again.width != image.width || again.height != image.height ||
        again.values.size() != image.values.size() ||
        std::memcmp(again.values.data(), image.values.data(), image.values.size() * 4) != 0) {
      std::abort();
    }
  } catch (const facet::InputError&) {
  }
}

// The container's XML alone, then the whole container imported (profiles 2d, 3d and a3, the
// last also with an eye away from the origin).
FACET_FUZZ_TARGET(mpcdi) {
  try {
    facet::interop::parse_mpcdi_xml(text_of(bytes), "fuzz.xml");
  } catch (const facet::InputError&) {
  }
  try {
    const auto files = facet::interop::read_zip(text_of(bytes), "fuzz.mpcdi");
    facet::interop::import_mpcdi(files, "fuzz.mpcdi");
    facet::interop::MpcdiImportOptions options;
    options.eye = glm::dvec3(0.5, -0.25, 2.0);
    facet::interop::import_mpcdi(files, "fuzz.mpcdi", options);
  } catch (const facet::InputError&) {
  }
}

// Parsed, then imported at a small output size whose aspect follows the mesh.
FACET_FUZZ_TARGET(bourke) {
  try {
    const auto mesh = facet::interop::parse_bourke(text_of(bytes), "fuzz.data");
    facet::interop::BourkeImportOptions options;
    options.output_size = {int(std::max(2.0, std::min(256.0, 64 * mesh.aspect))), 64};
    options.warp_grid = {17, 17};
    facet::interop::import_bourke(mesh, options, "fuzz.data", "fuzz");
  } catch (const facet::InputError&) {
  }
}

// A SCISS .sgc mesh, or a SimCAD mesh for input starting with '<', imported at a small size.
FACET_FUZZ_TARGET(sgc) {
  const std::string_view text = text_of(bytes);
  try {
    facet::interop::SgcMesh frustum;
    frustum.up_deg = 30, frustum.down_deg = -30, frustum.left_deg = -40, frustum.right_deg = 40;
    const auto mesh = !text.empty() && text[0] == '<'
                          ? facet::interop::parse_simcad(text, frustum, "fuzz")
                          : facet::interop::parse_sgc(text, "fuzz.sgc");
    facet::interop::SgcImportOptions options;
    options.output_size = {64, 40};
    options.warp_grid = {17, 17};
    facet::interop::import_sgc(mesh, options, "fuzz.sgc", "fuzz");
  } catch (const facet::InputError&) {
  }
}

// An SGCT cluster file alone in its folder: the meshes it names are not there.
FACET_FUZZ_TARGET(sgct_xml) {
  try {
    facet::interop::SgctImportOptions options;
    options.warp_grid = {9, 9};
    facet::interop::import_sgct_cluster(write_scratch("cluster.xml", bytes), options);
  } catch (const facet::InputError&) {
  }
}
