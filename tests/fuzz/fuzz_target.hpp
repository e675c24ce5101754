#pragma once
// Fuzz entry points, one per parser: each takes arbitrary bytes and must end normally, with a
// result or with an InputError (the documented answer to bad input). Anything else is a finding:
// a crash, a sanitizer report, an abort, another exception escaping, or a hang.
//
// FACET_FUZZ_TARGET(name) { ... } defines an entry point and registers it. Two executables run
// them: `fuzz_replay` (any compiler; ctest) replays every file of the seed corpus through every
// target, and `facet_fuzz` (clang, -fsanitize=fuzzer; `tools/dev fuzz`) runs libFuzzer on the one
// target that FACET_FUZZ_TARGET in the environment names.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace facet::fuzz {

using Bytes = std::span<const std::uint8_t>;
using Entry = void (*)(Bytes);

struct Target {
  std::string name;
  Entry entry;
};

// Every registered target, sorted by name.
const std::vector<Target>& targets();
const Target* find_target(std::string_view name);

struct Registration {
  Registration(const char* name, Entry entry);
};

// The bytes as text (they may hold NULs and invalid UTF-8).
inline std::string_view text_of(Bytes bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

// A scratch folder of this process, created on first use and removed at exit; readers that take
// only a path read the bytes from a file written there.
const std::filesystem::path& scratch_folder();
// Writes `bytes` to scratch_folder() / name (replacing it) and returns that path.
std::filesystem::path write_scratch(const std::string& name, Bytes bytes);

}  // namespace facet::fuzz

#define FACET_FUZZ_TARGET(name)                                                               \
  static void facet_fuzz_##name(::facet::fuzz::Bytes bytes);                                  \
  static const ::facet::fuzz::Registration facet_fuzz_registration_##name{#name,              \
                                                                          facet_fuzz_##name}; \
  static void facet_fuzz_##name(::facet::fuzz::Bytes bytes)
