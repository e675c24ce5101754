// libFuzzer target: PFM files from arbitrary bytes; a parsed file must format back to bytes that
// parse to the same image.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "facet/interop/pfm.hpp"
#include "facet/projection/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const auto image = facet::interop::parse_pfm(bytes, "fuzz.pfm");
    const auto again = facet::interop::parse_pfm(facet::interop::format_pfm(image), "again.pfm");
    if (again.width != image.width || again.height != image.height ||
        again.values.size() != image.values.size() ||
        std::memcmp(again.values.data(), image.values.data(), image.values.size() * 4) != 0) {
      std::abort();
    }
  } catch (const facet::InputError&) {
  }
  return 0;
}
