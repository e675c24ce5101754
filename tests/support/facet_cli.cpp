#include "support/facet_cli.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

namespace facet::test {
namespace {

// In the sanitizer build, LeakSanitizer's own tracer thread sometimes crashes at exit, after the
// command did all its work ("Tracer caught signal 11", then "LeakSanitizer has encountered a fatal
// error", exit 1): with LSAN_OPTIONS=verbosity=1 it reports the main thread's dynamic TLS block
// 42 at 0x3b13-0x1800'0000'4c15, a record the sanitizer's tracking of dynamically loaded TLS got
// wrong, and faults reading it. 2 of 10 runs of RunCli.HeadlessSessionRendersTheSamePixelsAsRender
// here, with or without facet's signal handlers. That is the sanitizer failing, not facet and not
// a leak (a leak is reported as "LeakSanitizer: detected memory leaks"; use_tls=0 would avoid the
// crash but reports what only thread-local storage holds as leaks), so such a run is made again,
// up to kAttemptsAfterSanitizerFailure times in all, and said so.
constexpr int kAttemptsAfterSanitizerFailure = 4;
bool leak_sanitizer_tool_failed(int status, const std::string& output) {
  return status != 0 &&
         output.find("LeakSanitizer has encountered a fatal error") != std::string::npos;
}

// run() (an exit status) until it ends otherwise than in that failure, whose output() tells,
// kAttemptsAfterSanitizerFailure times at most; each attempt again is said.
template <typename Run, typename Output>
int run_past_sanitizer_tool_failures(const std::string& arguments, Run run, Output output) {
  int status = run();
  for (int attempt = 2;
       attempt <= kAttemptsAfterSanitizerFailure && leak_sanitizer_tool_failed(status, output());
       ++attempt) {
    std::printf("note: LeakSanitizer's tracer failed after `facet %s`; attempt %d\n",
                arguments.c_str(), attempt);
    status = run();
  }
  return status;
}

// The shell command that runs `facet <arguments>`, under timeout(1) with limit_s > 0.
std::string facet_command(const std::string& arguments, int limit_s) {
  const std::string limit = limit_s > 0 ? "timeout " + std::to_string(limit_s) + " " : "";
  return limit + std::string(FACET_CLI) + " " + arguments;
}

}  // namespace

int run_shell(const std::string& command, std::string* output) {
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

int run_facet(const std::string& arguments, const std::filesystem::path& log, int limit_s) {
  const std::string command = facet_command(arguments, limit_s) + " > " + log.string() + " 2>&1";
  return run_past_sanitizer_tool_failures(
      arguments, [&] { return run_shell(command); }, [&] { return slurp(log); });
}

int run_facet(const std::string& arguments, std::string* output, int limit_s) {
  std::string own;
  std::string& text = output ? *output : own;
  const std::string command = facet_command(arguments, limit_s);
  return run_past_sanitizer_tool_failures(
      arguments, [&] { return run_shell(command, &text); }, [&] { return text; });
}

pid_t start_facet(const std::vector<std::string>& arguments, const std::filesystem::path& log) {
  std::vector<std::string> argv_storage{"facet"};
  argv_storage.insert(argv_storage.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : argv_storage) argv.push_back(argument.data());
  argv.push_back(nullptr);
  const std::string log_path = log.string();
  const pid_t child = ::fork();
  if (child == 0) {
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    ::execv(FACET_CLI, argv.data());
    ::_exit(127);
  }
  return child;
}

bool catches_signal(pid_t process, int signal) {
  std::ifstream status("/proc/" + std::to_string(process) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (!line.starts_with("SigCgt:")) continue;
    unsigned long long mask = 0;
    std::istringstream(line.substr(7)) >> std::hex >> mask;
    return (mask >> (signal - 1)) & 1u;
  }
  return false;
}

bool wait_until(const std::function<bool()>& condition, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

int wait_for_exit(pid_t process) {
  int status = 0;
  if (::waitpid(process, &status, 0) != process) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace facet::test
