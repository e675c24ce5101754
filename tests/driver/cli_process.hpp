#pragma once
// Running the facet CLI (or any shell command) from a test, and reading what it wrote.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace facet::test {

// Exit status of a shell command, -1 when it did not exit normally. With `output`, its stdout and
// stderr together; without, they go where the command sends them.
inline int run_shell(const std::string& command, std::string* output = nullptr) {
  if (output == nullptr) {
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  output->clear();
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) *output += buffer;
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// `facet <arguments>` (FACET_CLI), its stdout and stderr written to `log`.
inline int run_facet(const std::string& arguments, const std::filesystem::path& log) {
  return run_shell(std::string(FACET_CLI) + " " + arguments + " > " + log.string() + " 2>&1");
}

// `facet <arguments>`, with its stdout and stderr in `output` when given.
inline int run_facet(const std::string& arguments, std::string* output = nullptr) {
  return run_shell(std::string(FACET_CLI) + " " + arguments, output);
}

// A file's bytes.
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

}  // namespace facet::test
