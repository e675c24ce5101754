#pragma once
// Running the facet CLI (FACET_CLI) or any shell command from a test, and reading what it wrote.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "support/files.hpp"

namespace facet::test {

// Exit status of a shell command, -1 when it did not exit normally. With `output`, its stdout and
// stderr together; without, they go where the command sends them.
int run_shell(const std::string& command, std::string* output = nullptr);

// `facet <arguments>` through the shell (so `arguments` may carry redirections), its exit status;
// with limit_s > 0 under timeout(1), which exits 124 on expiry. In the sanitizer build a run that
// LeakSanitizer's own tracer failed is made again (see facet_cli.cpp). Its stdout and stderr go
// together to `log`,
int run_facet(const std::string& arguments, const std::filesystem::path& log, int limit_s = 0);
// or into `output` when given, and are dropped otherwise.
int run_facet(const std::string& arguments, std::string* output = nullptr, int limit_s = 0);

// Starts `facet <arguments>` without a shell, its stdout and stderr going to `log`; returns its
// process id, or -1.
pid_t start_facet(const std::vector<std::string>& arguments, const std::filesystem::path& log);

// True once `process` has a handler installed for `signal` (its SigCgt mask in /proc).
bool catches_signal(pid_t process, int signal);

// Polls `condition` every 10 ms until it holds (true) or `timeout` passes (false).
bool wait_until(const std::function<bool()>& condition, std::chrono::seconds timeout);

// The exit status of `process` once it ends; -1 when a signal ended it.
int wait_for_exit(pid_t process);

}  // namespace facet::test
