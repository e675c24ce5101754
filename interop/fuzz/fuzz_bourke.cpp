// libFuzzer target: a Paul Bourke mesh from arbitrary bytes, parsed and imported at a small
// output size. Only results and InputErrors are allowed.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "facet/interop/bourke.hpp"
#include "facet/projection/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const facet::interop::BourkeMesh mesh = facet::interop::parse_bourke(text, "fuzz.data");
    facet::interop::BourkeImportOptions options;
    // Small outputs keep each run fast; the aspect follows the mesh so that the import proceeds.
    options.output_size = {int(std::max(2.0, std::min(256.0, 64 * mesh.aspect))), 64};
    options.warp_grid = {17, 17};
    facet::interop::import_bourke(mesh, options, "fuzz.data", "fuzz");
  } catch (const facet::InputError&) {
  }
  return 0;
}
