#pragma once
// --frames of facet run, render and bench: one limit, driver::kMaxFrames, for every command that
// renders frames.
#include <cstdint>
#include <string>

#include "facet/driver/session_runner.hpp"
#include "facet/projection/errors.hpp"

namespace facet::cli {

// `frames` when it is 1 to driver::kMaxFrames; otherwise an InputError naming --frames, the
// allowed range and the value given. Signed, so that a negative count is refused, not wrapped.
inline std::uint64_t checked_frames(std::int64_t frames) {
  if (frames < 1 || std::uint64_t(frames) > driver::kMaxFrames)
    throw InputError("command line", "--frames",
                     "a number of frames from 1 to " + std::to_string(driver::kMaxFrames) +
                         ", got " + std::to_string(frames));
  return std::uint64_t(frames);
}

}  // namespace facet::cli
