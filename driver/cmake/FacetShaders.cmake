# facet_embed_shaders(<target> DIR <folder>)
#
# Embeds every GLSL file under <folder> (.vert .frag .comp .geom .tesc .tese, one stage per file)
# into <target> at build time and validates each with glslangValidator; a GLSL error fails the
# build. At run time `facet::driver::embedded_shader("<path relative to folder>")` returns the
# text, so nothing reads shader files from disk.
find_program(FACET_GLSLANG_VALIDATOR glslangValidator REQUIRED)
set(FACET_EMBED_SHADER_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_shader.cmake)

function(facet_embed_shaders target)
  cmake_parse_arguments(ARG "" "DIR" "" ${ARGN})
  if(NOT ARG_DIR)
    message(FATAL_ERROR "facet_embed_shaders: DIR is required")
  endif()
  set(patterns)
  foreach(ext vert frag comp geom tesc tese)
    list(APPEND patterns ${ARG_DIR}/*.${ext})
  endforeach()
  file(GLOB_RECURSE shader_files CONFIGURE_DEPENDS ${patterns})
  list(SORT shader_files)

  set(gen_dir ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders)
  set(generated)
  set(declarations "")
  set(entries "")
  foreach(shader IN LISTS shader_files)
    file(RELATIVE_PATH name ${ARG_DIR} ${shader})
    string(MAKE_C_IDENTIFIER "shader_${name}" symbol)
    set(out ${gen_dir}/${symbol}.cpp)
    # Materials and the shading that calls them are compiled with the material interface in
    # front (driver/material_shader.hpp), and so validated.
    set(prelude "")
    if(name MATCHES "^(scene/material|scene/sun_and_sky|glc/glc_hit)\\.frag$"
       OR name MATCHES "^scene/materials/")
      set(prelude ${ARG_DIR}/scene/material_interface.frag)
    endif()
    add_custom_command(
      OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DSHADER=${shader} -DNAME=${name} -DSYMBOL=${symbol}
              -DOUT_CPP=${out} -DCHECK_DIR=${gen_dir}/check -DPRELUDE=${prelude}
              -DVALIDATOR=${FACET_GLSLANG_VALIDATOR} -P ${FACET_EMBED_SHADER_SCRIPT}
      DEPENDS ${shader} ${prelude} ${FACET_EMBED_SHADER_SCRIPT}
      COMMENT "Validating and embedding shaders/${name}"
      VERBATIM)
    list(APPEND generated ${out})
    string(APPEND declarations "std::string_view ${symbol}();\n")
    string(APPEND entries "    {\"${name}\", ${symbol}()},\n")
  endforeach()

  set(registry ${gen_dir}/shader_registry.cpp)
  set(registry_text "// Generated at configure time: the list of embedded shaders. Do not edit.\n")
  string(APPEND registry_text "#include \"facet/driver/shader_library.hpp\"\n\n")
  string(APPEND registry_text "namespace facet::driver::embedded {\n${declarations}}  // namespace facet::driver::embedded\n\n")
  string(APPEND registry_text "namespace facet::driver {\n\n")
  string(APPEND registry_text "std::span<const EmbeddedShader> embedded_shaders() {\n")
  string(APPEND registry_text "  using namespace embedded;\n")
  string(APPEND registry_text "  static const EmbeddedShader shaders[] = {\n${entries}    {\"\", {}}};\n")
  string(APPEND registry_text "  return {shaders, std::size(shaders) - 1};\n}\n\n")
  string(APPEND registry_text "}  // namespace facet::driver\n")
  file(CONFIGURE OUTPUT ${registry} CONTENT "${registry_text}" @ONLY)
  target_sources(${target} PRIVATE ${generated} ${registry})
endfunction()
