#include "facet/driver/direction_cache.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <system_error>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::driver {
namespace {

// Bump when WarpInverse's answers or this file's layout change.
constexpr std::uint32_t kFormatVersion = 1;
constexpr char kMagic[8] = {'F', 'A', 'C', 'E', 'T', 'D', 'I', 'R'};

struct Header {
  char magic[8];
  std::uint32_t version;
  std::int32_t width, height;
  std::uint32_t reserved;
  std::uint64_t key;
  std::uint64_t payload_digest;
};
static_assert(sizeof(Header) == 40);

struct Fnv1a {
  std::uint64_t state = 14695981039346656037ull;
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < size; ++k) {
      state ^= p[k];
      state *= 1099511628211ull;
    }
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
};

// FNV-1a over 64-bit words (then the remaining bytes): eight times fewer steps than bytewise,
// tens of megabytes being read at every start.
std::uint64_t payload_digest(const std::vector<glm::vec3>& v_eye) {
  const std::size_t size = v_eye.size() * sizeof(glm::vec3);
  const auto* bytes = reinterpret_cast<const unsigned char*>(v_eye.data());
  std::uint64_t state = 14695981039346656037ull;
  std::size_t k = 0;
  for (; k + 8 <= size; k += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + k, 8);
    state = (state ^ word) * 1099511628211ull;
  }
  for (; k < size; ++k) state = (state ^ bytes[k]) * 1099511628211ull;
  return state;
}

// A name direction_cache_file_name gives: 16 lower-case hex digits, ".dirs".
bool is_cache_file_name(const std::string& name) {
  if (name.size() != 21 || name.compare(16, 5, ".dirs") != 0) return false;
  return std::all_of(name.begin(), name.begin() + 16,
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

bool read_cached(const std::filesystem::path& path, const Warp& warp, std::uint64_t key,
                 std::vector<glm::vec3>& v_eye) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  Header header{};
  if (!in.read(reinterpret_cast<char*>(&header), sizeof header)) return false;
  if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0 || header.version != kFormatVersion ||
      header.width != warp.output_size.x || header.height != warp.output_size.y ||
      header.key != key) {
    return false;
  }
  v_eye.resize(std::size_t(warp.output_size.x) * std::size_t(warp.output_size.y));
  const auto size = std::streamsize(v_eye.size() * sizeof(glm::vec3));
  if (!in.read(reinterpret_cast<char*>(v_eye.data()), size) || in.peek() != EOF) return false;
  if (payload_digest(v_eye) != header.payload_digest) return false;
  // Used now: the last file trim_direction_cache removes. A read-only folder keeps the old time.
  std::error_code ignored;
  std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ignored);
  return true;
}

void write_cached(const std::filesystem::path& path, const Warp& warp, std::uint64_t key,
                  const std::vector<glm::vec3>& v_eye) {
  Header header{};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.version = kFormatVersion;
  header.width = warp.output_size.x;
  header.height = warp.output_size.y;
  header.key = key;
  header.payload_digest = payload_digest(v_eye);
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out.write(reinterpret_cast<const char*>(&header), sizeof header);
    out.write(reinterpret_cast<const char*>(v_eye.data()),
              std::streamsize(v_eye.size() * sizeof(glm::vec3)));
    out.close();
    if (!out) throw std::runtime_error("cannot write " + temporary.string());
  });
}

}  // namespace

std::uint64_t direction_cache_key(const Warp& warp) {
  Fnv1a hash;
  hash.value(kFormatVersion);
  hash.value(int(warp.base.kind));
  for (double v : warp.base.tan_extent) hash.value(v);
  hash.value(warp.base.fov_deg);
  for (double v : warp.base.azimuth_deg) hash.value(v);
  for (double v : warp.base.tan_elevation) hash.value(v);
  for (double v : warp.base.elevation_deg) hash.value(v);
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) hash.value(warp.R_eye_base[c][r]);
  }
  hash.value(warp.output_size.x);
  hash.value(warp.output_size.y);
  hash.value(warp.grid_size.x);
  hash.value(warp.grid_size.y);
  for (const glm::vec2& offset : warp.offset_px) {
    hash.value(offset.x);
    hash.value(offset.y);
  }
  hash.bytes(warp.coverage.data(), warp.coverage.size() * sizeof(float));
  return hash.state;
}

std::string direction_cache_file_name(std::uint64_t key) {
  static const char* hex = "0123456789abcdef";
  std::string name(16, '0');
  for (int k = 0; k < 16; ++k) name[15 - k] = hex[(key >> (4 * k)) & 15];
  return name + ".dirs";
}

std::size_t trim_direction_cache(const std::filesystem::path& folder, std::uint64_t budget_bytes,
                                 const std::filesystem::path& keep) {
  namespace fs = std::filesystem;
  struct Entry {
    fs::path path;
    fs::file_time_type time;
    std::uintmax_t size;
    bool kept;
  };
  std::vector<Entry> entries;
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    std::error_code entry_error;
    // symlink_status: a link named like a cache file is not the cache's and is left alone.
    if (!is_cache_file_name(name) || !fs::is_regular_file(it->symlink_status(entry_error)))
      continue;
    Entry entry{it->path(), it->last_write_time(entry_error), it->file_size(entry_error),
                !keep.empty() && name == keep.filename().string()};
    if (!entry_error) entries.push_back(std::move(entry));
  }
  // The kept file first, then the most recently used; ties by name, for the same order every time.
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    if (a.kept != b.kept) return a.kept;
    if (a.time != b.time) return a.time > b.time;
    return a.path < b.path;
  });
  std::uint64_t total = 0;
  std::size_t removed = 0;
  for (const Entry& entry : entries) {
    total += entry.size;
    if (entry.kept || total <= budget_bytes) continue;
    std::error_code ignored;
    if (fs::remove(entry.path, ignored)) ++removed;
  }
  return removed;
}

DirectionLookup direction_lookup(const Warp& warp, const std::filesystem::path& folder,
                                 std::uint64_t budget_bytes, std::stop_token stop) {
  DirectionLookup lookup;
  const std::uint64_t key = direction_cache_key(warp);
  const std::filesystem::path path =
      folder.empty() ? folder : folder / direction_cache_file_name(key);
  if (!folder.empty() && read_cached(path, warp, key, lookup.v_eye)) {
    lookup.from_cache = true;
    return lookup;
  }
  if (stop.stop_requested()) return {{}, false, true};
  lookup.v_eye = WarpInverse(warp).v_eye_at_pixel_centres(0, stop);
  // An inverse stopped part-way is incomplete: neither returned nor cached.
  if (stop.stop_requested()) return {{}, false, true};
  if (!folder.empty()) {
    try {
      std::error_code ignored;
      std::filesystem::create_directories(folder, ignored);
      write_cached(path, warp, key, lookup.v_eye);
      trim_direction_cache(folder, budget_bytes, path);
    } catch (const std::exception&) {
      // A read-only or full disk: the next start computes the directions again.
    }
  }
  return lookup;
}

std::filesystem::path default_direction_cache() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "facet" / "directions";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "facet" / "directions";
  return {};
}

}  // namespace facet::driver
