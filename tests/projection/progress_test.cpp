#include "facet/projection/progress.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace facet {
namespace {

std::string contents(std::FILE* file) {
  std::rewind(file);
  std::string text;
  for (int c = std::fgetc(file); c != EOF; c = std::fgetc(file)) text += char(c);
  return text;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(TerminalProgress, FormatsCountBarAndTimeLeft) {
  EXPECT_EQ(TerminalProgress::format("facet run", {"frames", 100, 300}, 10.0, false),
            "facet run: frames 100/300, 20 s left");
  EXPECT_EQ(TerminalProgress::format("facet run", {"frames", 150, 300}, 200.0, true),
            "facet run: frames [############............] 150/300, 3 min left");
  EXPECT_EQ(TerminalProgress::format("facet run", {"frames", 300, 300}, 12.4, false),
            "facet run: frames 300/300, 12 s");
  EXPECT_EQ(TerminalProgress::format("bench", {"settings", 7, 0}, 1.0, true), "bench: settings 7");
}

// Not on a terminal: a line at the start, at every tenth and at the end, and one after 10 s
// without any; never a carriage return.
TEST(TerminalProgress, WritesPlainLinesAtEveryTenthWhenNotOnATerminal) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    TerminalProgress progress(file, "facet run", TerminalProgress::Style::lines);
    const auto start = TerminalProgress::Clock::now();
    for (std::uint64_t k = 0; k <= 300; ++k)
      progress.report({"frames", k, 300}, start + std::chrono::milliseconds(100 * k));
    // A slow job of unknown length: a line only when 10 s have passed.
    for (std::uint64_t k = 0; k < 40; ++k)
      progress.report({"patterns", k, 0}, start + std::chrono::seconds(31 + k));
  }
  const std::string text = contents(file);
  std::fclose(file);
  EXPECT_EQ(count(text, "facet run: frames "), 11u) << text;
  EXPECT_NE(text.find("facet run: frames 0/300\n"), std::string::npos) << text;
  EXPECT_NE(text.find("facet run: frames 30/300, 27 s left\n"), std::string::npos) << text;
  EXPECT_NE(text.find("facet run: frames 300/300, 30 s\n"), std::string::npos) << text;
  EXPECT_EQ(count(text, "facet run: patterns "), 4u) << text;  // at 31, 41, 51 and 61 s
  EXPECT_EQ(text.find('\r'), std::string::npos);
}

// On a terminal: one line redrawn in place at most every 100 ms, ended by a newline when the work
// is done, so that what follows starts on a line of its own.
TEST(TerminalProgress, RedrawsOneLineOnATerminal) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    TerminalProgress progress(file, "facet run", TerminalProgress::Style::terminal);
    const auto start = TerminalProgress::Clock::now();
    for (std::uint64_t k = 0; k <= 300; ++k)
      progress.report({"frames", k, 300}, start + std::chrono::milliseconds(10 * k));
  }
  const std::string text = contents(file);
  std::fclose(file);
  EXPECT_EQ(count(text, "\n"), 1u) << text;
  EXPECT_EQ(text.back(), '\n');
  // 3 s of steps every 10 ms: about one redraw per 100 ms, plus the first and the last.
  EXPECT_GE(count(text, "\r"), 30u);
  EXPECT_LE(count(text, "\r"), 33u);
  EXPECT_NE(text.find("[########################] 300/300, 3 s\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace facet
