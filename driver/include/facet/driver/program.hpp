#pragma once
// Builds GL programs from embedded shaders (or from text, for tests and tools).
//
// Every stage is compiled as
//     #version 450 core            (or the file's own #version line, moved up)
//     #define NAME VALUE           (the caller's defines, in order)
//     #line 1                      (so the driver numbers lines as in the original file)
//     <the file's text>
// A compile or link error throws ShaderError naming the file and the line in that file.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/gl_objects.hpp"

namespace facet::driver {

enum class ShaderStage { vertex, tess_control, tess_evaluation, geometry, fragment, compute };

// The stage for a file name's extension (.vert .tesc .tese .geom .frag .comp). Throws
// std::invalid_argument for any other extension.
ShaderStage stage_from_name(std::string_view name);
GLenum gl_shader_type(ShaderStage stage);

// A shader failed to compile, or a program failed to link. what() holds the driver's log with
// every "0:LINE" rewritten as "FILE:LINE". For compile errors file() and line() locate the first
// error in the original file (line 0 when the driver gave no line); for link errors file() lists
// the program's files and line() is 0.
class ShaderError : public std::runtime_error {
 public:
  ShaderError(std::string message, std::string file, int line, std::string log)
      : std::runtime_error(std::move(message)),
        file_(std::move(file)),
        line_(line),
        log_(std::move(log)) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& log() const { return log_; }  // the driver's log, unchanged

 private:
  std::string file_;
  int line_;
  std::string log_;
};

struct ShaderDefine {
  std::string name;
  std::string value;  // may be empty: `#define NAME`
};

// The exact text handed to the GL for one stage (see the header comment). Exposed for tests.
std::string compose_shader_source(std::string_view text, const std::vector<ShaderDefine>& defines);

// Compiles one stage; throws ShaderError with `file_name` on failure. Needs a current context.
Shader compile_shader(ShaderStage stage, std::string_view file_name, std::string_view text,
                      const std::vector<ShaderDefine>& defines = {});

class ProgramBuilder {
 public:
  // Adds `#define name value` to every stage of the program.
  ProgramBuilder& define(std::string name, std::string value = "1");
  ProgramBuilder& define(std::string name, long long value);
  // Adds an embedded shader by name ("scene/mesh.vert"); the extension gives the stage.
  ProgramBuilder& shader(std::string_view embedded_name);
  // Adds a stage from text; `file_name` is what errors report.
  ProgramBuilder& source(ShaderStage stage, std::string file_name, std::string text);
  // Compiles every stage and links. Throws ShaderError. Needs a current context.
  Program link() const;

 private:
  struct Stage {
    ShaderStage stage;
    std::string file_name;
    std::string text;
  };
  std::vector<ShaderDefine> defines_;
  std::vector<Stage> stages_;
};

// Shorthand: link the named embedded shaders with these defines.
Program build_program(std::initializer_list<std::string_view> embedded_names,
                      const std::vector<ShaderDefine>& defines = {});

}  // namespace facet::driver
