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
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet::driver {

struct DirectionLookup {
  std::vector<glm::vec3> v_eye;  // WarpInverse::v_eye_at_pixel_centres()
  bool from_cache = false;       // read from the cache folder, not computed
};

// The digest naming the warp's cache file.
std::uint64_t direction_cache_key(const Warp& warp);

// The directions of `warp`'s output pixel centres: read from `folder` when it holds a valid file
// for this warp, else computed and (when `folder` is not empty) written there. Failing to create
// the folder or write the file only costs the next start the time: the result is the same.
DirectionLookup direction_lookup(const Warp& warp, const std::filesystem::path& folder);

// The default cache folder: $XDG_CACHE_HOME/facet/directions, else ~/.cache/facet/directions;
// empty when neither variable is set.
std::filesystem::path default_direction_cache();

}  // namespace facet::driver
