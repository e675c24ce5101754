#pragma once
// Progress of long work (frames rendered, patterns simulated, settings benchmarked).
//
// Libraries report steps through a ProgressSink and never print. The command line gives them a
// TerminalProgress: on a terminal one line redrawn in place with a bar, the count and the time
// left; elsewhere (a log, a pipe) a plain line at every tenth of the work and at most every 10 s
// otherwise, so that logs stay short and still show a stalled job.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

namespace facet {

struct ProgressStep {
  std::string_view what;              // the work, e.g. "frames" or "dome4 facets tol=1px"
  std::uint64_t done = 0, total = 0;  // steps finished of all; total 0 when unknown
};
using ProgressSink = std::function<void(const ProgressStep&)>;

class TerminalProgress {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Style { automatic, terminal, lines };  // automatic: terminal when `out` is a tty

  // `label` starts every line, e.g. "facet run".
  TerminalProgress(std::FILE* out, std::string label, Style style = Style::automatic);
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;
  // Ends the redrawn line on a terminal.
  ~TerminalProgress();

  void report(const ProgressStep& step) { report(step, Clock::now()); }
  // The same at a given time (tests).
  void report(const ProgressStep& step, Clock::time_point now);
  // A sink that reports here; valid while this object lives.
  ProgressSink sink() {
    return [this](const ProgressStep& step) { report(step); };
  }
  // Ends a redrawn line (before other output), so that the next report starts a new one.
  void finish();

  // "label: what [#####.....] 37/300, 12 s left": the line a step gives after `elapsed` since the
  // first step of its work.
  static std::string format(std::string_view label, const ProgressStep& step, double elapsed_s,
                            bool bar);

 private:
  std::FILE* out_;
  std::string label_;
  bool terminal_;
  std::string what_;                   // the work of the last step
  Clock::time_point started_, shown_;  // its first step, the last line shown
  std::uint64_t shown_tenth_ = 0;      // lines: the last tenth of the work shown
  bool line_open_ = false;             // terminal: a redrawn line without its newline
};

}  // namespace facet
