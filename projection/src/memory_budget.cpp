#include "facet/projection/memory_budget.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr std::uint64_t kUnknown = std::numeric_limits<std::uint64_t>::max();

// Bytes this process maps now (/proc/self/statm's first field, in pages).
std::uint64_t mapped_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  if (!(statm >> pages)) return 0;
  return pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

std::uint64_t system_available_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string line;
  std::uint64_t available = 0, swap_free = 0;
  bool found = false;
  while (std::getline(meminfo, line)) {
    std::istringstream fields(line);
    std::string key;
    std::uint64_t kib = 0;
    if (!(fields >> key >> kib)) continue;
    if (key == "MemAvailable:") available = kib * 1024, found = true;
    if (key == "SwapFree:") swap_free = kib * 1024;
  }
  return found ? available + swap_free : kUnknown;
}

std::string gib(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f GiB", static_cast<double>(bytes) / double(1 << 30));
  return text;
}

}  // namespace

std::uint64_t allocatable_bytes() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const std::uint64_t mapped = mapped_bytes();
    const auto cap = static_cast<std::uint64_t>(limit.rlim_cur);
    return cap > mapped ? cap - mapped : 0;
  }
  return system_available_bytes();
}

void require_memory(std::uint64_t bytes, const std::string& source, const InputField& field,
                    const std::string& what) {
  const std::uint64_t budget = allocatable_bytes();
  if (bytes <= budget) return;
  throw InputError(source, field,
                   what + " needs about " + gib(bytes) + ", more than the " + gib(budget) +
                       " this process can still allocate");
}

}  // namespace facet
