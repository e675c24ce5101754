// libFuzzer target: an MPCDI container (zip, XML, PFM, PNG members; profiles 2d, 3d and a3)
// from arbitrary bytes. Any input must end in a result or an InputError; anything else (a crash,
// a sanitizer report, an assertion, another exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "facet/interop/mpcdi.hpp"
#include "facet/projection/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    facet::interop::parse_mpcdi_xml(bytes, "fuzz.xml");
  } catch (const facet::InputError&) {
  }
  try {
    const auto files = facet::interop::read_zip(bytes, "fuzz.mpcdi");
    facet::interop::import_mpcdi(files, "fuzz.mpcdi");
    // Profile a3 with an eye away from the origin: points at or behind it, units, origins.
    facet::interop::MpcdiImportOptions options;
    options.eye = glm::dvec3(0.5, -0.25, 2.0);
    facet::interop::import_mpcdi(files, "fuzz.mpcdi", options);
  } catch (const facet::InputError&) {
  }
  return 0;
}
