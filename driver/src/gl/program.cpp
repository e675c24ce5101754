#include "facet/driver/program.hpp"

#include <regex>
#include <sstream>

#include "facet/driver/shader_library.hpp"

namespace facet::driver {

namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// True when the line's first token is the #version directive.
bool is_version_line(std::string_view line) {
  std::size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  if (i == line.size() || line[i] != '#') return false;
  ++i;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  return line.substr(i, 7) == "version";
}

// Rewrites the driver's "0:LINE" (Mesa) and "0(LINE)" (NVIDIA) locations as "FILE:LINE", and
// finds the first error's line. Only source string 0 is used, so "0" always means this file.
std::string locate_log(std::string_view log, std::string_view file, int& first_error_line) {
  static const std::regex location(R"(^(\s*(?:ERROR:\s*|WARNING:\s*)?)0(?::(\d+)|\((\d+)\)))");
  first_error_line = 0;
  std::string out;
  std::istringstream lines{std::string(log)};
  for (std::string line; std::getline(lines, line);) {
    std::smatch match;
    if (std::regex_search(line, match, location)) {
      const std::string number = match[2].matched ? match[2].str() : match[3].str();
      if (first_error_line == 0 && line.find("error") != std::string::npos)
        first_error_line = std::stoi(number);
      line = match[1].str() + std::string(file) + ":" + number + match.suffix().str();
    }
    out += line + "\n";
  }
  return out;
}

std::string info_log(GLuint object, bool is_program) {
  GLint length = 0;
  if (is_program)
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  else
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  if (length <= 1) return {};
  std::string log(static_cast<std::size_t>(length), '\0');
  GLsizei written = 0;
  if (is_program)
    glGetProgramInfoLog(object, length, &written, log.data());
  else
    glGetShaderInfoLog(object, length, &written, log.data());
  log.resize(static_cast<std::size_t>(written));
  return log;
}

}  // namespace

ShaderStage stage_from_name(std::string_view name) {
  if (ends_with(name, ".vert")) return ShaderStage::vertex;
  if (ends_with(name, ".tesc")) return ShaderStage::tess_control;
  if (ends_with(name, ".tese")) return ShaderStage::tess_evaluation;
  if (ends_with(name, ".geom")) return ShaderStage::geometry;
  if (ends_with(name, ".frag")) return ShaderStage::fragment;
  if (ends_with(name, ".comp")) return ShaderStage::compute;
  throw std::invalid_argument(
      "stage_from_name: '" + std::string(name) +
      "' has no shader stage extension (.vert .tesc .tese .geom .frag .comp)");
}

GLenum gl_shader_type(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::vertex:
      return GL_VERTEX_SHADER;
    case ShaderStage::tess_control:
      return GL_TESS_CONTROL_SHADER;
    case ShaderStage::tess_evaluation:
      return GL_TESS_EVALUATION_SHADER;
    case ShaderStage::geometry:
      return GL_GEOMETRY_SHADER;
    case ShaderStage::fragment:
      return GL_FRAGMENT_SHADER;
    case ShaderStage::compute:
      return GL_COMPUTE_SHADER;
  }
  return GL_VERTEX_SHADER;
}

std::string compose_shader_source(std::string_view text, const std::vector<ShaderDefine>& defines) {
  std::string version = "#version 450 core";
  std::string body;
  body.reserve(text.size());
  // A #version in the file moves to the top; its line stays, empty, so numbering is unchanged.
  bool found = false;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    if (!found && is_version_line(line)) {
      version = std::string(line);
      found = true;
    } else {
      body += line;
    }
    if (end == text.size()) break;
    body += '\n';
    start = end + 1;
  }
  std::string out = version + "\n";
  for (const auto& define : defines) out += "#define " + define.name + " " + define.value + "\n";
  out += "#line 1\n";
  out += body;
  return out;
}

Shader compile_shader(ShaderStage stage, std::string_view file_name, std::string_view text,
                      const std::vector<ShaderDefine>& defines) {
  Shader shader = Shader::create(gl_shader_type(stage));
  const std::string source = compose_shader_source(text, defines);
  const char* pointer = source.c_str();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(shader.id(), 1, &pointer, &length);
  glCompileShader(shader.id());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(shader.id(), false);
    int line = 0;
    const std::string located = locate_log(log, file_name, line);
    throw ShaderError("shader compile error in " + std::string(file_name) +
                          (line > 0 ? " at line " + std::to_string(line) : std::string()) + ":\n" +
                          located,
                      std::string(file_name), line, log);
  }
  return shader;
}

ProgramBuilder& ProgramBuilder::define(std::string name, std::string value) {
  defines_.push_back({std::move(name), std::move(value)});
  return *this;
}

ProgramBuilder& ProgramBuilder::define(std::string name, long long value) {
  return define(std::move(name), std::to_string(value));
}

ProgramBuilder& ProgramBuilder::shader(std::string_view embedded_name) {
  const EmbeddedShader& embedded = embedded_shader(embedded_name);
  stages_.push_back({stage_from_name(embedded.name), "shaders/" + std::string(embedded.name),
                     std::string(embedded.text)});
  return *this;
}

ProgramBuilder& ProgramBuilder::source(ShaderStage stage, std::string file_name, std::string text) {
  stages_.push_back({stage, std::move(file_name), std::move(text)});
  return *this;
}

Program ProgramBuilder::link() const {
  std::string files;
  for (const auto& stage : stages_) files += (files.empty() ? "" : ", ") + stage.file_name;
  if (stages_.empty()) throw ShaderError("program link error: no shader stages", "", 0, "");
  std::vector<Shader> shaders;
  for (const auto& stage : stages_)
    shaders.push_back(compile_shader(stage.stage, stage.file_name, stage.text, defines_));
  Program program = Program::create();
  for (const auto& shader : shaders) glAttachShader(program.id(), shader.id());
  glLinkProgram(program.id());
  // Detached shaders are freed with their wrappers; the program keeps its binary.
  for (const auto& shader : shaders) glDetachShader(program.id(), shader.id());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(program.id(), true);
    throw ShaderError("program link error (" + files + "):\n" + log, files, 0, log);
  }
  return program;
}

Program build_program(std::initializer_list<std::string_view> embedded_names,
                      const std::vector<ShaderDefine>& defines) {
  ProgramBuilder builder;
  for (const auto& define : defines) builder.define(define.name, define.value);
  for (const auto name : embedded_names) builder.shader(name);
  return builder.link();
}

}  // namespace facet::driver
