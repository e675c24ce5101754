// Replays every file of the seed corpus folders (or the files) given on the command line through
// every fuzz target (or those named by --target), in one process: the check that runs in ctest
// under the normal and the sanitizer builds. A finding (crash, sanitizer report, abort, an
// exception other than InputError, or an input running over --timeout seconds) stops the run with
// the target and the file named on stderr and a non-zero exit status.
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <typeinfo>
#include <vector>

#include "fuzz_target.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#endif

namespace {

namespace fs = std::filesystem;

// What runs now, kept in fixed buffers so that a signal handler can print it.
char current_target[128] = "";
char current_file[1024] = "";

void write_stderr(const char* text) {
  const ssize_t ignored = ::write(2, text, std::strlen(text));
  (void)ignored;
}

void report_current(const char* what) {
  write_stderr("fuzz_replay: ");
  write_stderr(what);
  write_stderr(" in target '");
  write_stderr(current_target);
  write_stderr("' on file ");
  write_stderr(current_file);
  write_stderr("\n");
}

void on_fatal_signal(int signal) {
  report_current(signal == SIGALRM ? "hang (over the time limit)" : ::strsignal(signal));
  ::signal(signal, SIG_DFL);
  if (signal == SIGALRM) ::_exit(3);
  ::raise(signal);
}

#if defined(__SANITIZE_ADDRESS__)
void on_sanitizer_death() { report_current("sanitizer report"); }
#endif

void copy_name(char (&buffer)[128], const std::string& text) {
  std::snprintf(buffer, sizeof buffer, "%s", text.c_str());
}
void copy_name(char (&buffer)[1024], const std::string& text) {
  std::snprintf(buffer, sizeof buffer, "%s", text.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> folders;
  std::vector<std::string> only;
  unsigned timeout_s = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--target" && i + 1 < argc) {
      only.push_back(argv[++i]);
    } else if (arg == "--timeout" && i + 1 < argc) {
      timeout_s = unsigned(std::stoul(argv[++i]));
    } else if (arg == "--list") {
      for (const auto& target : facet::fuzz::targets()) std::cout << target.name << "\n";
      return 0;
    } else {
      folders.emplace_back(arg);
    }
  }
  if (folders.empty()) {
    std::cerr << "usage: fuzz_replay [--target NAME]... [--timeout S] [--list] FOLDER|FILE...\n";
    return 2;
  }
  std::vector<fs::path> files;
  for (const fs::path& folder : folders) {
    std::error_code ec;
    if (fs::is_regular_file(folder, ec)) {  // a single input, such as a libFuzzer finding
      files.push_back(folder);
      continue;
    }
    for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::end(it);
         it.increment(ec)) {
      if (it->is_regular_file()) files.push_back(it->path());
    }
    if (ec) {
      std::cerr << "fuzz_replay: cannot read " << folder << ": " << ec.message() << "\n";
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<const facet::fuzz::Target*> chosen;
  for (const auto& target : facet::fuzz::targets()) {
    if (only.empty() || std::find(only.begin(), only.end(), target.name) != only.end()) {
      chosen.push_back(&target);
    }
  }
  if (chosen.empty() || files.empty()) {
    std::cerr << "fuzz_replay: no target or no file to replay\n";
    return 2;
  }

#if !defined(__SANITIZE_ADDRESS__)  // ASan reserves terabytes of address space
  // A memory blow-up is a finding, as it is for libFuzzer's -rss_limit_mb.
  const rlimit limit{rlim_t{2} << 30, rlim_t{2} << 30};
  ::setrlimit(RLIMIT_AS, &limit);
#else
  __sanitizer_set_death_callback(on_sanitizer_death);
#endif
  for (const int signal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGALRM}) {
    struct sigaction action {};
    action.sa_handler = on_fatal_signal;
    ::sigaction(signal, &action, nullptr);
  }

  const auto start = std::chrono::steady_clock::now();
  std::size_t runs = 0;
  for (const fs::path& file : files) {
    std::ifstream stream(file, std::ios::binary);
    const std::string data{std::istreambuf_iterator<char>(stream),
                           std::istreambuf_iterator<char>()};
    const facet::fuzz::Bytes bytes(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
    copy_name(current_file, file.string());
    for (const facet::fuzz::Target* target : chosen) {
      copy_name(current_target, target->name);
      ::alarm(timeout_s);
      try {
        target->entry(bytes);
      } catch (const std::exception& e) {
        report_current("an exception escaped");
        std::cerr << "  " << typeid(e).name() << ": " << e.what() << "\n";
        return 1;
      } catch (...) {
        report_current("an exception of unknown type escaped");
        return 1;
      }
      ::alarm(0);
      ++runs;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "fuzz_replay: " << files.size() << " files x " << chosen.size()
            << " targets = " << runs << " runs, no finding, " << seconds << " s\n";
  return 0;
}
