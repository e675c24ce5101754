#pragma once
// The CLI's log sink for the runtime (facet/driver/log.hpp): info lines on stdout, warnings on
// stderr, each after `prefix` ("facet run: "), flushed at once.
#include <cstdio>
#include <string>

#include "facet/driver/log.hpp"

namespace facet::cli {

inline driver::LogSink console_log(std::string prefix) {
  return [prefix = std::move(prefix)](driver::LogLevel level, const std::string& line) {
    std::FILE* out = level == driver::LogLevel::warning ? stderr : stdout;
    std::fprintf(out, "%s%s\n", prefix.c_str(), line.c_str());
    std::fflush(out);
  };
}

}  // namespace facet::cli
