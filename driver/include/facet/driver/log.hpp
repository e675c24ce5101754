#pragma once
// Where the runtime tells its operator what happens in a run: one line per call, without the
// program's name. The program decides where lines go (the CLI: info on stdout, warnings on
// stderr, each after "facet run: " or "facet play: "); an empty sink says nothing.
#include <functional>
#include <string>

namespace facet::driver {

enum class LogLevel { info, warning };
using LogSink = std::function<void(LogLevel level, const std::string& line)>;

}  // namespace facet::driver
