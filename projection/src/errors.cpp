#include "facet/projection/errors.hpp"

#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace facet {

namespace {

std::mutex failed_mutex;
std::string failed_activity;

}  // namespace

Activity::Activity(std::string what)
    : what_(std::move(what)), exceptions_at_start_(std::uncaught_exceptions()) {
  const std::lock_guard lock(failed_mutex);
  failed_activity.clear();
}

Activity::~Activity() {
  if (std::uncaught_exceptions() <= exceptions_at_start_) return;
  // Unwinding: the innermost step is destroyed first and keeps its name; moving the string
  // allocates nothing, which matters when the exception is std::bad_alloc.
  const std::lock_guard lock(failed_mutex);
  if (failed_activity.empty()) failed_activity = std::move(what_);
}

const std::string& InputError::option() const {
  static const std::string none;
  return option_ == Option::source ? source_ : option_ == Option::field ? field_ : none;
}

InputError InputError::with_option_shown_as(const std::string& shown) const {
  switch (option_) {
    case Option::source:
      return InputError(shown, field_, expected_);
    case Option::field:
      return InputError(source_, shown, expected_);
    case Option::none:
      break;
  }
  return *this;
}

std::string Activity::failed() {
  const std::lock_guard lock(failed_mutex);
  return failed_activity;
}

void assertion_failed(const char* function, const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s: assertion '%s' failed (%s:%d)\n", function, condition, file, line);
  std::abort();
}

}  // namespace facet
