#include "facet/driver/material_shader.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "facet/driver/shader_library.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"

namespace facet::driver {
namespace {

constexpr std::array<std::string_view, 4> kBuiltins = {"lit", "solid-wireframe", "pen-and-ink",
                                                       "procedural"};
constexpr std::uintmax_t kMaxMaterialBytes = 1 << 20;

std::string builtin_file(std::string_view name) {
  return "scene/materials/" + std::string(name) + ".frag";
}

// The text without comments, newlines kept so that line numbers stay.
std::string without_comments(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
      if (i < text.size()) out += '\n';
    } else if (text.compare(i, 2, "/*") == 0) {
      i += 2;
      while (i < text.size() && text.compare(i, 2, "*/") != 0) {
        if (text[i] == '\n') out += '\n';
        ++i;
      }
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

// InputError when the material's text uses a word that would let it change IDs or depth.
void refuse_forbidden_words(const std::string& file, std::string_view text) {
  static const std::regex forbidden(R"(\b(discard|gl_FragDepth)\b)");
  const std::string code = without_comments(text);
  std::smatch match;
  if (!std::regex_search(code, match, forbidden)) return;
  const auto line = 1 + std::count(code.begin(), code.begin() + match.position(0), '\n');
  throw InputError(file, OptionName{"material"},
                   "line " + std::to_string(line) + " uses '" + match[1].str() +
                       "': a material only returns a colour from shade(), so that the triangle "
                       "IDs and depth stay the renderer's");
}

// InputError when the material's bytes are not UTF-8 text: a NUL byte would cut the source short
// where the GL reads it, and invalid UTF-8 has no meaning in GLSL (not even in a comment).
void refuse_non_text(const std::string& file, std::string_view text) {
  std::size_t line = 1;
  for (std::size_t i = 0; i < text.size();) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte == '\n') ++line;
    if (byte == 0) {
      throw InputError(file, OptionName{"material"},
                       "line " + std::to_string(line) + " holds a NUL byte: expected GLSL text");
    }
    // The length of the UTF-8 sequence this byte starts (0: not a valid start byte).
    const std::size_t length = byte < 0x80                   ? 1
                               : byte >= 0xc2 && byte < 0xe0 ? 2
                               : byte >= 0xe0 && byte < 0xf0 ? 3
                               : byte >= 0xf0 && byte < 0xf5 ? 4
                                                             : 0;
    bool valid = length > 0 && i + length <= text.size();
    for (std::size_t k = 1; valid && k < length; ++k) {
      valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
    }
    if (!valid) {
      throw InputError(file, OptionName{"material"},
                       "line " + std::to_string(line) + " is not valid UTF-8: expected GLSL text");
    }
    i += length;
  }
}

// A minimal vertex stage that feeds scene/material.frag, for check_material_shader.
constexpr std::string_view kCheckVertex = R"(
out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
void main() {
  v_n_world = vec3(0.0, 1.0, 0.0);
  v_uv = vec2(0.0);
  v_p_world = vec3(0.0);
  v_p_eye = vec3(0.0, 0.0, -1.0);
  v_barycentric = vec3(float(gl_VertexID == 0), float(gl_VertexID == 1), float(gl_VertexID == 2));
  v_triangle_id = 1u;
  gl_Position = vec4(0.0, 0.0, 0.5, 1.0);
}
)";

// What compiler messages name for the material.
std::string material_file(const MaterialShader& material) {
  if (!material.file.empty()) return material.file;
  if (material.text.empty()) return "shaders/" + builtin_file(material.name);
  return material.name;
}

}  // namespace

std::span<const std::string_view> builtin_material_names() { return kBuiltins; }

MaterialShader load_material_shader(std::string_view name_or_file) {
  for (std::string_view name : kBuiltins) {
    if (name == name_or_file) {
      MaterialShader material;
      material.name = std::string(name);
      material.file = "shaders/" + builtin_file(name);
      material.text = std::string(embedded_shader(builtin_file(name)).text);
      return material;
    }
  }
  const std::string file(name_or_file);
  if (!file.ends_with(".frag")) {
    throw InputError("command line", OptionName{"material"},
                     "expected lit, solid-wireframe, pen-and-ink, procedural or a GLSL file "
                     "FILE.frag; got '" +
                         file + "'");
  }
  require_regular_file(file);
  std::error_code error;
  const auto bytes = std::filesystem::file_size(file, error);
  if (error || bytes > kMaxMaterialBytes) {
    throw InputError(file, OptionName{"material"}, "expected a GLSL file of at most 1 MiB");
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof())
    throw InputError(file, OptionName{"material"}, "expected a readable GLSL file");
  MaterialShader material;
  material.name = file;
  material.file = file;
  material.text = text.str();
  refuse_non_text(file, material.text);
  refuse_forbidden_words(file, material.text);
  return material;
}

std::string material_stage_text(std::string_view material_text) {
  std::string text(embedded_shader("scene/material_interface.frag").text);
  text += "\n#line 1\n";
  text += material_text;
  return text;
}

void add_material_stages(ProgramBuilder& builder, const MaterialShader& material,
                         std::string_view gather) {
  builder.source(ShaderStage::fragment, "shaders/" + std::string(gather),
                 material_stage_text(embedded_shader(gather).text));
  builder.source(ShaderStage::fragment, "shaders/scene/sun_and_sky.frag",
                 material_stage_text(embedded_shader("scene/sun_and_sky.frag").text));
  if (material.text.empty()) {
    const MaterialShader builtin = load_material_shader(material.name);
    builder.source(ShaderStage::fragment, builtin.file, material_stage_text(builtin.text));
  } else {
    builder.source(ShaderStage::fragment, material_file(material),
                   material_stage_text(material.text));
  }
}

namespace {

// The material stages with a minimal vertex stage: what check_material_shader links.
ProgramBuilder material_check_program(const MaterialShader& material) {
  ProgramBuilder builder;
  builder.define("WRITE_TRIANGLE_ID", "1");
  builder.source(ShaderStage::vertex, "material check", std::string(kCheckVertex));
  add_material_stages(builder, material);
  return builder;
}

bool material_links_alone(const MaterialShader& material) {
  try {
    material_check_program(material).link();
    return true;
  } catch (const ShaderError&) {
    return false;
  }
}

}  // namespace

Program link_with_material(const ProgramBuilder& builder, const MaterialShader& material) {
  const std::string file = material_file(material);
  try {
    return builder.link();
  } catch (const ShaderError& e) {
    if (e.file().find(file) == std::string::npos) throw;
    const bool compile = e.file() == file;
    // A program that fails to link although the material links alone is facet's own error: the
    // whole driver log goes up.
    if (!compile && material_links_alone(material)) throw;
    // The driver's first error line, the material's own where it names the file.
    std::string first;
    std::istringstream lines(e.log());
    for (std::string line; std::getline(lines, line);) {
      if (line.find("error") == std::string::npos && line.find("ERROR") == std::string::npos)
        continue;
      if (first.empty() || line.find(file + ":") != std::string::npos) first = line;
      if (line.find(file + ":") != std::string::npos) break;
    }
    if (first.empty()) first = e.what();
    throw InputError(
        file, OptionName{"material"},
        std::string(compile ? "GLSL compile error" : "GLSL link error") +
            (compile && e.line() > 0 ? " at line " + std::to_string(e.line()) : std::string()) +
            ": " + first +
            " (a material defines vec4 shade(MaterialInput m): see "
            "shaders/scene/material_interface.frag)");
  }
}

void check_material_shader(const MaterialShader& material) {
  link_with_material(material_check_program(material), material);
}

}  // namespace facet::driver
