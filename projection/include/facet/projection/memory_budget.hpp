#pragma once
// Memory a step will need, checked before it allocates: a size nobody's machine can hold gets an
// InputError in a moment instead of std::bad_alloc (or the kernel's OOM killer) minutes later.
#include <cstdint>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet {

// Bytes this process can still allocate: its address-space limit (RLIMIT_AS, as `ulimit -v`
// sets it) less what it maps now, or without a limit what the system reports available
// (MemAvailable plus SwapFree in /proc/meminfo). UINT64_MAX when neither is known.
std::uint64_t allocatable_bytes();

// InputError(source, field, ...) naming `what`, the estimate and the budget when `bytes` is more
// than allocatable_bytes().
void require_memory(std::uint64_t bytes, const std::string& source, const InputField& field,
                    const std::string& what);

}  // namespace facet
