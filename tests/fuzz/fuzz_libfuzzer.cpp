// libFuzzer's entry points (clang, -fsanitize=fuzzer): the target that FACET_FUZZ_TARGET in the
// environment names. `tools/dev fuzz` sets it.
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "fuzz_target.hpp"

namespace {
const facet::fuzz::Target* chosen = nullptr;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* name = std::getenv("FACET_FUZZ_TARGET");
  if (name && std::string_view(name) == "list") {
    for (const auto& target : facet::fuzz::targets()) std::printf("%s\n", target.name.c_str());
    std::exit(0);
  }
  chosen = name ? facet::fuzz::find_target(name) : nullptr;
  if (!chosen) {
    std::fprintf(stderr, "facet_fuzz: set FACET_FUZZ_TARGET to one of:");
    for (const auto& target : facet::fuzz::targets())
      std::fprintf(stderr, " %s", target.name.c_str());
    std::fprintf(stderr, "\n");
    std::exit(2);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  chosen->entry(facet::fuzz::Bytes(data, size));
  return 0;
}
