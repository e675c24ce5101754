#pragma once
// Error types shared by every facet library.
//
// InputError is the user's fault (a bad file, field or flag): it names the source, the field and
// what was expected, and the CLI turns it into exit status 2. Programmer errors are assertions
// (FACET_ASSERT) whose message starts with the function name.
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

[[noreturn]] void assertion_failed(const char* function, const char* condition, const char* file,
                                   int line);

}  // namespace facet

#define FACET_ASSERT(condition) \
  ((condition) ? void(0) : ::facet::assertion_failed(__func__, #condition, __FILE__, __LINE__))
