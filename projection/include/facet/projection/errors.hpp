#pragma once
// Error types shared by every facet library.
//
// InputError is the user's fault (a bad file, field or option): it names the source, the field and
// what was expected, and the CLI turns it into exit status 2. Programmer errors are assertions
// (FACET_ASSERT) whose message starts with the function name.
//
// A library names a refused option of its call by the option's library name (OptionName: the
// field of its options struct, "fov_deg", or the parameter, "scene"), never by a command-line
// flag; the CLI shows each under the flag that sets it (tools/cli/option_flags.hpp).
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>

namespace facet {

// The library name of an option of a call: "fov_deg" for ContentProjection::fov_deg.
struct OptionName {
  std::string name;
};

// What an InputError names within its source: a field ("render.tolerance_px", or the CLI's flag
// "--out") or an option of a library call by its library name (OptionName). A helper that checks
// a value for its caller takes one, so that a library passes it an option and the CLI a flag.
class InputField {
 public:
  InputField() = default;
  InputField(const char* field) : name_(field) {}
  InputField(std::string field) : name_(std::move(field)) {}
  InputField(std::string_view field) : name_(field) {}
  InputField(OptionName option) : name_(std::move(option.name)), option_(true) {}

  const std::string& name() const { return name_; }
  bool is_option() const { return option_; }
  bool empty() const { return name_.empty(); }

 private:
  std::string name_;
  bool option_ = false;
};

class InputError : public std::runtime_error {
 public:
  // "SOURCE: field 'FIELD': EXPECTED"; "SOURCE: EXPECTED" without a field. An option as the
  // field is refused for what it says of `source` (a file it names, or the command line):
  // "command line: field 'fov_deg': expected ...".
  InputError(std::string source, const InputField& field, std::string expected)
      : InputError(std::move(source), field.name(), std::move(expected),
                   field.is_option() ? Option::field : Option::none) {}
  // An option refused on its own, named as the source: "average: a number of exposures >= 1".
  InputError(OptionName option, std::string expected)
      : InputError(std::move(option.name), "", std::move(expected), Option::source) {}

  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }
  const std::string& expected() const { return expected_; }

  // The library name of the option this error refuses; "" when it names no option.
  const std::string& option() const;
  // The same error with its option shown as `shown` (the CLI passes the option's flag) where the
  // library name stood; an error that names no option comes back as it is.
  InputError with_option_shown_as(const std::string& shown) const;

 private:
  enum class Option { none, source, field };  // where the option's name stands
  InputError(std::string source, std::string field, std::string expected, Option option)
      : std::runtime_error(compose(source, field, expected)),
        source_(std::move(source)),
        field_(std::move(field)),
        expected_(std::move(expected)),
        option_(option) {}
  static std::string compose(const std::string& source, const std::string& field,
                             const std::string& expected) {
    std::string message = source.empty() ? std::string("input") : source;
    if (!field.empty()) message += ": field '" + field + "'";
    return message + ": " + expected;
  }
  std::string source_, field_, expected_;
  Option option_ = Option::none;
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
