// libFuzzer target: a SCISS .sgc mesh (or, for input starting with '<', a SimCAD .simcad file)
// from arbitrary bytes, parsed and imported at a small output size. Only results and InputErrors
// are allowed.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "facet/interop/sgc.hpp"
#include "facet/projection/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    facet::interop::SgcMesh frustum;
    frustum.up_deg = 30, frustum.down_deg = -30, frustum.left_deg = -40, frustum.right_deg = 40;
    const facet::interop::SgcMesh mesh = !bytes.empty() && bytes[0] == '<'
                                             ? facet::interop::parse_simcad(bytes, frustum, "fuzz")
                                             : facet::interop::parse_sgc(bytes, "fuzz.sgc");
    facet::interop::SgcImportOptions options;
    // Small outputs and a fixed grid keep each run fast.
    options.output_size = {64, 40};
    options.warp_grid = {17, 17};
    facet::interop::import_sgc(mesh, options, "fuzz.sgc", "fuzz");
  } catch (const facet::InputError&) {
  }
  return 0;
}
