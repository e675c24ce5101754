#pragma once
// The direction lookup of an output (the unit eye direction at every pixel centre, through the
// warp inverse), kept on disk so that the next start with the same warp reads it back instead of
// inverting the warp again (facet play, ContentPass).
//
// One file per warp in the cache folder, named by a 64-bit FNV-1a digest of the warp's exact
// content: base projection and its parameters, rotation, output and grid sizes, every node's
// offset and coverage bits, and kFormatVersion (bumped whenever the inverse or the file changes).
// The file holds a header (magic, version, size, digest, a digest of the payload) and the
// directions as float x, y, z per pixel, row 0 at the top, NaN where uncovered. It is written
// through write_atomically (a temporary file renamed into place), so a reader never sees a
// partial file; a file that does not match in any field is ignored and rewritten.
//
// The folder is bounded: after writing a file, the least recently used cache files beyond a
// budget of bytes (kDefaultDirectionCacheBudget unless given) are removed, "used" being the
// modification time, which a successful read sets to the present. Only regular files named as
// the cache names them (16 lower-case hex digits, ".dirs") are counted or removed, and never the
// file just written. A reader holding a removed file open still reads all of it (POSIX unlinks
// the name, not the open file), and a reader opening it afterwards finds none and computes.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <stop_token>
#include <string>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet::driver {

struct DirectionLookup {
  std::vector<glm::vec3> v_eye;  // WarpInverse::v_eye_at_pixel_centres()
  bool from_cache = false;       // read from the cache folder, not computed
  bool stopped = false;          // stopped on request: v_eye is empty, nothing was written
};

// 1 GiB: 28 displays of four 1024×768 outputs (37.7 MB each).
constexpr std::uint64_t kDefaultDirectionCacheBudget = std::uint64_t(1) << 30;

// The digest naming the warp's cache file.
std::uint64_t direction_cache_key(const Warp& warp);
// The cache file's name for `key`: 16 lower-case hex digits and ".dirs".
std::string direction_cache_file_name(std::uint64_t key);

// The directions of `warp`'s output pixel centres: read from `folder` when it holds a valid file
// for this warp, else computed and (when `folder` is not empty) written there, then the folder
// trimmed to `budget_bytes` (trim_direction_cache). Failing to create the folder or write the
// file only costs the next start the time: the result is the same. Once `stop` is requested the
// inverse stops after the rows under way, and the lookup comes back `stopped`, with no
// directions and no file written.
DirectionLookup direction_lookup(const Warp& warp, const std::filesystem::path& folder,
                                 std::uint64_t budget_bytes = kDefaultDirectionCacheBudget,
                                 std::stop_token stop = {});

// Removes the least recently modified cache files of `folder` until the rest total at most
// `budget_bytes`, newest kept first; `keep` (a file name in the folder) is never removed and
// counts first. Other files and folders are neither counted nor touched. Errors (a file gone
// meanwhile, a read-only folder) are ignored. Returns how many files were removed.
std::size_t trim_direction_cache(const std::filesystem::path& folder, std::uint64_t budget_bytes,
                                 const std::filesystem::path& keep = {});

// The default cache folder: $XDG_CACHE_HOME/facet/directions, else ~/.cache/facet/directions;
// empty when neither variable is set.
std::filesystem::path default_direction_cache();

}  // namespace facet::driver
