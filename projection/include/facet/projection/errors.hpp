#pragma once
// Error types shared by every facet library.
//
// InputError is the user's fault (a bad file, field or flag): it names the source, the field and
// what was expected, and the CLI turns it into exit status 2. Programmer errors are assertions
// (FACET_ASSERT) whose message starts with the function name.
#include <exception>
#include <stdexcept>
#include <string>

namespace facet {

class InputError : public std::runtime_error {
 public:
  InputError(std::string source, std::string field, std::string expected)
      : std::runtime_error(compose(source, field, expected)),
        source_(std::move(source)),
        field_(std::move(field)),
        expected_(std::move(expected)) {}

  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }
  const std::string& expected() const { return expected_; }

 private:
  static std::string compose(const std::string& source, const std::string& field,
                             const std::string& expected) {
    std::string message = source.empty() ? std::string("input") : source;
    if (!field.empty()) message += ": field '" + field + "'";
    return message + ": " + expected;
  }
  std::string source_, field_, expected_;
};

// A run that stopped because a process it works with went away: a cluster's master, or one of
// its critical nodes. The message names it; the CLI turns it into exit status 3.
class PeerLost : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A resource an input asks for could not be had: memory, or a GL object (a framebuffer of the
// requested size). Like InputError it is the input's fault: the CLI reports it with exit status 2,
// naming what the command was doing (Activity).
class ResourceExhausted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What the command is doing, for errors that carry no context of their own: std::bad_alloc, a
// ResourceExhausted, a library's exception. Declare one for the duration of a step, naming the
// step and its input ("reading the warp p0.warp.exr"). When an exception leaves the step, the
// innermost Activity it leaves is remembered until the next Activity starts; the CLI names it.
class Activity {
 public:
  explicit Activity(std::string what);
  ~Activity();
  Activity(const Activity&) = delete;
  Activity& operator=(const Activity&) = delete;

  // The step the last exception left, or "" when it left none (or a step started since).
  static std::string failed();

 private:
  std::string what_;
  int exceptions_at_start_;
};

[[noreturn]] void assertion_failed(const char* function, const char* condition, const char* file,
                                   int line);

}  // namespace facet

#define FACET_ASSERT(condition) \
  ((condition) ? void(0) : ::facet::assertion_failed(__func__, #condition, __FILE__, __LINE__))
