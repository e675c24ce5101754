#include "facet/projection/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace facet {
namespace {

constexpr auto kTerminalRedraw = std::chrono::milliseconds(100);
constexpr auto kQuietLines = std::chrono::seconds(10);
constexpr int kBarWidth = 24;

std::string format_seconds(double s) {
  char text[32];
  if (s < 100) {
    std::snprintf(text, sizeof text, "%.0f s", s);
  } else if (s < 6000) {
    std::snprintf(text, sizeof text, "%.0f min", s / 60);
  } else {
    std::snprintf(text, sizeof text, "%.1f h", s / 3600);
  }
  return text;
}

}  // namespace

TerminalProgress::TerminalProgress(std::FILE* out, std::string label, Style style)
    : out_(out),
      label_(std::move(label)),
      terminal_(style == Style::terminal ||
                (style == Style::automatic && ::isatty(::fileno(out)) == 1)) {}

TerminalProgress::~TerminalProgress() { finish(); }

std::string TerminalProgress::format(std::string_view label, const ProgressStep& step,
                                     double elapsed_s, bool bar) {
  std::string line = std::string(label) + ": " + std::string(step.what);
  if (step.total == 0) return line + " " + std::to_string(step.done);
  const double fraction = std::clamp(double(step.done) / double(step.total), 0.0, 1.0);
  if (bar) {
    const int filled = int(std::floor(fraction * kBarWidth));
    line += " [" + std::string(std::size_t(filled), '#') +
            std::string(std::size_t(kBarWidth - filled), '.') + "]";
  }
  line += " " + std::to_string(step.done) + "/" + std::to_string(step.total);
  if (step.done > 0 && step.done < step.total && elapsed_s > 0) {
    line += ", " + format_seconds(elapsed_s / fraction - elapsed_s) + " left";
  } else if (step.done >= step.total) {
    line += ", " + format_seconds(elapsed_s);
  }
  return line;
}

void TerminalProgress::report(const ProgressStep& step, Clock::time_point now) {
  if (step.what != what_ || step.done == 0) {
    if (step.what != what_) finish();
    what_ = std::string(step.what);
    started_ = now;
    shown_ = now - kQuietLines;
    shown_tenth_ = 0;
  }
  const double elapsed_s = std::chrono::duration<double>(now - started_).count();
  const bool last = step.total > 0 && step.done >= step.total;
  if (terminal_) {
    if (!last && line_open_ && now - shown_ < kTerminalRedraw) return;
    std::fprintf(out_, "\r\033[K%s", format(label_, step, elapsed_s, true).c_str());
    line_open_ = true;
    if (last) finish();
  } else {
    const std::uint64_t tenth = step.total > 0 ? step.done * 10 / step.total : 0;
    const bool new_tenth = step.total > 0 && tenth > shown_tenth_;
    if (!last && !new_tenth && now - shown_ < kQuietLines) return;
    shown_tenth_ = std::max(shown_tenth_, tenth);
    std::fprintf(out_, "%s\n", format(label_, step, elapsed_s, false).c_str());
  }
  shown_ = now;
  std::fflush(out_);
}

void TerminalProgress::finish() {
  if (!line_open_) return;
  std::fprintf(out_, "\n");
  std::fflush(out_);
  line_open_ = false;
}

}  // namespace facet
