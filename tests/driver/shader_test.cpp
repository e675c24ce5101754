// Embedded shaders: all of them compile on the test driver, and compile or link errors name the
// file and the line of the original file, whatever preamble the builder added.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>
#include <string>

#include "facet/driver/facet_gpu.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/shader_library.hpp"
#include "facet/projection/coverage_grid.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

TEST(Shaders, LibraryHoldsTheShaderFiles) {
  const auto shaders = embedded_shaders();
  ASSERT_GE(shaders.size(), 5u);
  for (std::size_t i = 1; i < shaders.size(); ++i)
    EXPECT_LT(shaders[i - 1].name, shaders[i].name) << "embedded_shaders() must be sorted";
  const EmbeddedShader& fill = embedded_shader("test/fill_ssbo.comp");
  EXPECT_NE(fill.text.find("values[i] = i * i + offset"), std::string_view::npos);
  EXPECT_THROW(embedded_shader("test/no_such_shader.frag"), std::out_of_range);
}

// The coverage grid's constants exist twice, in CoverageGrid and in the GLSL that mirrors it.
TEST(Shaders, CoverageGridConstantsMatchTheCpp) {
  const std::string text(embedded_shader("replication/replication_lib.comp").text);
  const auto value = [&](const std::string& name) {
    std::smatch match;
    const std::regex pattern(name + R"( = (\d+)u)");
    EXPECT_TRUE(std::regex_search(text, match, pattern)) << name;
    return match.empty() ? -1L : std::stol(match[1]);
  };
  EXPECT_EQ(value("kGridMaxBuckets"), long(CoverageGrid::kMaxBuckets));
  EXPECT_EQ(value("kGridMaxCandidates"), long(CoverageGrid::kMaxCandidates));
  EXPECT_EQ(value("kChartCylindrical"), long(CoverageChart::cylindrical));
  EXPECT_EQ(value("kChartEquirectangular"), long(CoverageChart::equirectangular));
  EXPECT_EQ(value("kChartFisheye"), long(CoverageChart::fisheye));
  EXPECT_EQ(value("kChartPerspective"), long(CoverageChart::perspective));
  const auto real = [&](const std::string& name) {
    std::smatch match;
    const std::regex pattern(name + R"( = ([0-9.e+-]+);)");
    EXPECT_TRUE(std::regex_search(text, match, pattern)) << name;
    return match.empty() ? -1.0 : std::stod(match[1]);
  };
  EXPECT_EQ(real("kGnomonicMinDepth"), CoverageGrid::kGnomonicMinDepth);
  EXPECT_EQ(real("kGnomonicPad"), CoverageGrid::kGnomonicPad);
}

// grid_query's answers (replication_lib.comp) are read by the passes that queue on them,
// count.comp and count_wide.comp, each with its own copy of the values it tests.
TEST(Shaders, GridQueryAnswersMatchTheLibrary) {
  const auto value = [](const char* shader, const std::string& name) {
    const std::string text(embedded_shader(shader).text);
    std::smatch match;
    EXPECT_TRUE(std::regex_search(text, match, std::regex(name + R"( = (\d+)u)")))
        << shader << ": " << name;
    return match.empty() ? -1L : std::stol(match[1]);
  };
  const char* library = "replication/replication_lib.comp";
  EXPECT_EQ(value("replication/count.comp", "kGridWide"), value(library, "kGridWide"));
  for (const char* name : {"kGridEmpty", "kGridWalk"})
    EXPECT_EQ(value("replication/count_wide.comp", name), value(library, name)) << name;
}

// Pass 1's staging layout exists four times: facet_gpu.hpp, count.comp, count_wide.comp and
// scatter.comp.
TEST(Shaders, StagingConstantsMatchTheCpp) {
  for (const char* name :
       {"replication/count.comp", "replication/count_wide.comp", "replication/scatter.comp"}) {
    SCOPED_TRACE(name);
    const std::string text(embedded_shader(name).text);
    std::smatch match;
    ASSERT_TRUE(std::regex_search(text, match, std::regex(R"(kKept = (\d+)u)")));
    EXPECT_EQ(std::stoul(match[1]), kStagedChunkFacets);
    ASSERT_TRUE(std::regex_search(text, match, std::regex(R"(kChained = 0x([0-9a-f]+)u)")));
    EXPECT_EQ(std::stoul(match[1], nullptr, 16), kStagedChained);
  }
}

// The list's block size, the clusters' sphere markers and the texture units of the scatter and of
// the coverage grid exist twice: facet_gpu.hpp and the GLSL.
TEST(Shaders, ListAndScatterConstantsMatchTheCpp) {
  std::smatch match;
  const std::string library(embedded_shader("replication/replication_lib.comp").text);
  ASSERT_TRUE(std::regex_search(library, match, std::regex(R"(kListBlockTriangles = (\d+)u)")));
  EXPECT_EQ(std::stoul(match[1]), kListBlockTriangles);
  const std::string list_build(embedded_shader("replication/list_build.comp").text);
  ASSERT_TRUE(std::regex_search(list_build, match, std::regex(R"(kTableBlockTriangles = (\d+)u)")));
  EXPECT_EQ(std::stoul(match[1]), kListBlockTriangles);
  ASSERT_TRUE(std::regex_search(
      list_build, match,
      std::regex(R"(kClusterCulledAlways = (-?[0-9.]+), kClusterAsObject = (-?[0-9.]+);)")));
  EXPECT_EQ(std::stof(match[1]), kClusterCulledAlways);
  EXPECT_EQ(std::stof(match[2]), kClusterAsObject);
  const std::string scatter(embedded_shader("replication/scatter.comp").text);
  for (const auto& [text, name, unit] :
       {std::tuple<const std::string*, const char*, GLuint>{&scatter, "scan_texels",
                                                            texture_unit::scan},
        {&scatter, "staged_texels", texture_unit::staged},
        {&scatter, "stage_offset_texels", texture_unit::stage_offsets},
        {&library, "grid_texels", texture_unit::grid},
        {&library, "grid_vec4_texels", texture_unit::grid_vec4},
        {&library, "node_texels", texture_unit::nodes},
        {&library, "order_texels", texture_unit::order}}) {
    ASSERT_TRUE(std::regex_search(
        *text, match,
        std::regex(R"(binding = (\d+)\) uniform usamplerBuffer )" + std::string(name))))
        << name;
    EXPECT_EQ(std::stoul(match[1]), unit) << name;
  }
}

// The replication passes' storage-buffer bindings exist twice: binding:: (facet_gpu.hpp) and the
// layout of every shader that declares the block. Each block is found somewhere, and wherever it
// is declared its binding is the C++ one.
TEST(Shaders, StorageBufferBindingsMatchTheCpp) {
  const std::map<std::string, GLuint> bindings = {
      {"Indices", binding::indices},
      {"Scan", binding::scan},
      {"Pairs", binding::pairs},
      {"Stats", binding::stats},
      {"MaterialRanges", binding::material_ranges},
      {"DrawArgs", binding::draw_args},
      {"BlockSums", binding::block_sums},
      {"Staged", binding::staged},
      {"StageOffsets", binding::stage_offsets},
      {"DrawCounts", binding::draw_counts},
      {"WalkQueue", binding::walk_queue},
      {"GridQueue", binding::grid_queue},
      {"WideQueue", binding::wide_queue},
      {"ListOut", binding::list_out},
      {"ObjectSpheres", binding::object_spheres},
      {"ObjectVisible", binding::object_visible},
      {"ListArgs", binding::list_args},
      {"EntryRecords", binding::entry_records},
      {"MaterialFirstEntries", binding::material_first_entries},
      {"ClusterSpheres", binding::cluster_spheres},
      {"EntryStates", binding::entry_states}};
  std::map<std::string, int> found;
  const std::regex block(R"(layout\(std430, binding = (\d+)\) (?:[a-z]+ )*buffer (\w+))");
  for (const EmbeddedShader& shader : embedded_shaders()) {
    const std::string text(shader.text);
    std::string block_name;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), block);
         it != std::sregex_iterator(); ++it) {
      block_name = (*it)[2];
      // The prefix scan's data is whichever buffer is bound at binding::scan.
      if (shader.name == "replication/scan.comp" && block_name == "Data") block_name = "Scan";
      const auto expected = bindings.find(block_name);
      if (expected == bindings.end()) continue;
      ++found[block_name];
      EXPECT_EQ(std::stoul((*it)[1]), expected->second) << shader.name << ": " << block_name;
    }
  }
  for (const auto& [name, value] : bindings)
    EXPECT_GT(found[name], 0) << name << " is declared nowhere";
}

// The material shading block's binding is written in gpu_scene.hpp and in each stage that gathers
// MaterialInput: material.frag and the GLC ray cast's glc_hit.frag.
TEST(Shaders, MaterialShadingBindingMatchesTheCpp) {
  for (const char* name : {"scene/material.frag", "glc/glc_hit.frag"}) {
    const std::string text(embedded_shader(name).text);
    std::smatch match;
    ASSERT_TRUE(std::regex_search(
        text, match, std::regex(R"(layout\(std140, binding = (\d+)\) uniform MaterialShading)")))
        << name;
    EXPECT_EQ(std::stoul(match[1]), material_shading_binding) << name;
  }
}

// Explicit uniform locations are program-wide, and every replication stage links with
// replication_lib.comp: a location the library uses may not name another uniform there, and a
// stage's uniform may not take the name of one of the library's functions. llvmpipe links such
// programs when one of the two is unused; NVIDIA's linker refuses both.
TEST(Shaders, ReplicationUniformsAgreeWithTheLibrary) {
  const std::regex declaration(R"(layout\(location = (\d+)\) uniform \w+ (\w+)(\[)?)");
  const auto locations = [&](std::string_view name) {
    std::map<int, std::string> names;
    const std::string text(embedded_shader(name).text);
    for (std::sregex_iterator it(text.begin(), text.end(), declaration), end; it != end; ++it) {
      EXPECT_FALSE((*it)[3].matched) << name << ": array uniform " << (*it)[2]
                                     << " takes several locations; this test reads one";
      names[std::stoi((*it)[1])] = (*it)[2];
    }
    return names;
  };
  const auto library = locations("replication/replication_lib.comp");
  ASSERT_GE(library.size(), 3u);
  std::set<std::string> library_functions;
  const std::string library_text(embedded_shader("replication/replication_lib.comp").text);
  const std::regex function(R"((?:^|\n)\w+ (\w+)\()");
  for (std::sregex_iterator it(library_text.begin(), library_text.end(), function), end; it != end;
       ++it)
    library_functions.insert((*it)[1]);
  ASSERT_TRUE(library_functions.contains("record")) << "the library's functions were not read";
  const std::regex any_uniform(R"(uniform \w+ (\w+)\s*;)");
  int stages = 0;
  for (const EmbeddedShader& shader : embedded_shaders()) {
    if (!shader.name.starts_with("replication/") ||
        shader.name == "replication/replication_lib.comp")
      continue;
    ++stages;
    const std::string text(shader.text);
    for (std::sregex_iterator it(text.begin(), text.end(), any_uniform), end; it != end; ++it) {
      EXPECT_FALSE(library_functions.contains((*it)[1]))
          << shader.name << ": uniform " << (*it)[1] << " has a library function's name";
    }
    for (const auto& [location, name] : locations(shader.name)) {
      const auto in_library = library.find(location);
      if (in_library != library.end()) {
        EXPECT_EQ(in_library->second, name) << shader.name << ": location " << location;
      }
      for (const auto& [library_location, library_name] : library) {
        if (library_name == name) {
          EXPECT_EQ(library_location, location) << shader.name << ": uniform " << name;
        }
      }
    }
  }
  EXPECT_GE(stages, 10);
}

TEST(Shaders, EveryEmbeddedShaderCompiles) {
  test::shared_context();
  for (const EmbeddedShader& shader : embedded_shaders()) {
    SCOPED_TRACE(std::string(shader.name));
    // Materials and the shading that calls them compile with the material interface in front.
    const std::string_view name = shader.name;
    const bool material = name == "scene/material.frag" || name == "scene/sun_and_sky.frag" ||
                          name == "glc/glc_hit.frag" || name.starts_with("scene/materials/");
    const std::string text = material ? material_stage_text(shader.text) : std::string(shader.text);
    EXPECT_NO_THROW({
      Shader compiled = compile_shader(stage_from_name(shader.name), shader.name, text);
      EXPECT_NE(compiled.id(), 0u);
    });
  }
}

TEST(Shaders, ComposedSourceKeepsLineNumbers) {
  const std::string composed = compose_shader_source(
      "// comment\n#version 460 core\nvoid main() {}\n", {{"A", "1"}, {"B", ""}});
  EXPECT_EQ(composed,
            "#version 460 core\n#define A 1\n#define B \n#line 1\n// comment\n\nvoid main() {}\n");
  EXPECT_EQ(compose_shader_source("void main() {}", {}),
            "#version 450 core\n#line 1\nvoid main() {}");
}

// Line 6 of this text has the error. It is an undeclared name rather than a missing semicolon,
// because drivers report a missing semicolon on the line of the next token.
constexpr const char* broken_fragment =
    "// A shader with one error.\n"            // 1
    "layout(location = 0) out vec4 colour;\n"  // 2
    "\n"                                       // 3
    "void main() {\n"                          // 4
    "  vec4 base = vec4(SCALE);\n"             // 5
    "  colour = base * undeclared_name;\n"     // 6
    "}\n";                                     // 7

TEST(Shaders, CompileErrorNamesFileAndLine) {
  test::shared_context();
  const std::vector<ShaderDefine> defines = {{"SCALE", "0.5"}, {"UNUSED_A", "1"}, {"UNUSED_B", ""}};
  try {
    compile_shader(ShaderStage::fragment, "shaders/broken.frag", broken_fragment, defines);
    FAIL() << "expected ShaderError";
  } catch (const ShaderError& e) {
    EXPECT_EQ(e.file(), "shaders/broken.frag");
    EXPECT_EQ(e.line(), 6) << e.what();
    EXPECT_NE(std::string(e.what()).find("shaders/broken.frag:6"), std::string::npos) << e.what();
  }
}

TEST(Shaders, CompileErrorLineWithTheFilesOwnVersion) {
  test::shared_context();
  // The file's own #version (line 2) moves above the defines; numbering must not shift.
  const std::string text = std::string("// header\n#version 450 core\n") +
                           "layout(location = 0) out vec4 colour;\n"  // 3
                           "void main() {\n"                          // 4
                           "  colour = vec4(missing);\n"              // 5
                           "}\n";
  try {
    ProgramBuilder().define("X", 3).source(ShaderStage::fragment, "own_version.frag", text).link();
    FAIL() << "expected ShaderError";
  } catch (const ShaderError& e) {
    EXPECT_EQ(e.file(), "own_version.frag");
    EXPECT_EQ(e.line(), 5) << e.what();
  }
}

TEST(Shaders, LinkErrorNamesTheProgramsFiles) {
  test::shared_context();
  ProgramBuilder builder;
  builder.source(ShaderStage::vertex, "a.vert", "void main() { gl_Position = vec4(0.0); }\n");
  builder.source(ShaderStage::fragment, "b.frag",
                 "in vec4 never_written;\nlayout(location = 0) out vec4 c;\n"
                 "void main() { c = never_written; }\n");
  try {
    builder.link();
    FAIL() << "expected ShaderError";
  } catch (const ShaderError& e) {
    EXPECT_NE(e.file().find("a.vert"), std::string::npos);
    EXPECT_NE(e.file().find("b.frag"), std::string::npos);
    EXPECT_EQ(e.line(), 0);
  }
}

TEST(Shaders, EmbeddedErrorsUseTheShadersPath) {
  test::shared_context();
  // A bad define breaks the fragment shader where the macro is used; the error names the
  // embedded file by its path under shaders/.
  try {
    ProgramBuilder()
        .shader("test/triangle.vert")
        .shader("test/triangle.frag")
        .define("TEST_COLOUR_SCALE", "not a number +")
        .link();
    FAIL() << "expected ShaderError";
  } catch (const ShaderError& e) {
    EXPECT_EQ(e.file(), "shaders/test/triangle.frag") << e.what();
  }
}

TEST(Shaders, StageFromName) {
  EXPECT_EQ(stage_from_name("x/y.vert"), ShaderStage::vertex);
  EXPECT_EQ(stage_from_name("y.tesc"), ShaderStage::tess_control);
  EXPECT_EQ(stage_from_name("y.tese"), ShaderStage::tess_evaluation);
  EXPECT_EQ(stage_from_name("y.geom"), ShaderStage::geometry);
  EXPECT_EQ(stage_from_name("y.frag"), ShaderStage::fragment);
  EXPECT_EQ(stage_from_name("y.comp"), ShaderStage::compute);
  EXPECT_THROW(stage_from_name("y.glsl"), std::invalid_argument);
}

}  // namespace
}  // namespace facet::driver
