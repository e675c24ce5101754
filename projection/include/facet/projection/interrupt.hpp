#pragma once
// Stopping a long command cleanly on SIGINT (Ctrl-C) or SIGTERM.
//
// A command that polls calls watch_interrupts() once; its long loops then call
// throw_if_interrupted() (or read interrupt_signal()) between steps. The exception unwinds through
// the writers' temporary-then-rename code, which removes the temporary outputs, and the CLI turns
// it into one line saying what was done and exit status 128 + the signal number (130 for SIGINT,
// 143 for SIGTERM). Each handler is reset to the default by its first signal, so a second Ctrl-C
// ends the process at once. Code that never called watch_interrupts() is never interrupted.
#include <atomic>
#include <csignal>
#include <stdexcept>
#include <string>
#include <string_view>

namespace facet {

class Interrupted : public std::runtime_error {
 public:
  // `what`: what was done and what is left, e.g. "stopped after 37 of 300 frames; nothing
  // written to out/session".
  Interrupted(int signal, const std::string& what) : std::runtime_error(what), signal_(signal) {}
  int signal() const { return signal_; }
  // The conventional status of a process stopped by `signal`: 128 + its number.
  int exit_status() const { return 128 + signal_; }

 private:
  int signal_;
};

namespace interrupt_detail {
// The signal received, 0 for none. Lock-free, so that the handler may store it
// (async-signal-safe).
inline std::atomic<int> received{0};
static_assert(std::atomic<int>::is_always_lock_free);
inline void on_signal(int signal) { received.store(signal); }
}  // namespace interrupt_detail

// Installs the SIGINT and SIGTERM handlers, each reset to the default by its first signal, and
// forgets any signal received before.
inline void watch_interrupts() {
  interrupt_detail::received.store(0);
  struct sigaction action = {};
  action.sa_handler = interrupt_detail::on_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: the first signal restores the default action, so a second one ends the process.
  // SA_RESTART: reads and writes interrupted by the signal resume instead of failing.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

// The signal received since watch_interrupts() (SIGINT or SIGTERM), or 0.
inline int interrupt_signal() { return interrupt_detail::received.load(); }

// "SIGINT", "SIGTERM" or "signal N".
inline std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

// Throws Interrupted(interrupt_signal(), what) when a signal was received.
inline void throw_if_interrupted(std::string_view what) {
  if (const int signal = interrupt_signal()) throw Interrupted(signal, std::string(what));
}

}  // namespace facet
