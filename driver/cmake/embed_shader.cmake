# Build-time step for one GLSL file, run as `cmake -P embed_shader.cmake` with
#   SHADER     the GLSL file
#   NAME       its name relative to shaders/ (what the program builder looks up)
#   SYMBOL     the C identifier for the generated accessor
#   OUT_CPP    the generated C++ file
#   CHECK_DIR  scratch folder for the copy that glslangValidator reads
#   VALIDATOR  the glslangValidator executable
#
# The shader is validated first, so a GLSL error fails the build and no generated file is left
# behind. Files without `#version` get the runtime's `#version 450 core` prepended for the check,
# followed by `#line 1` so that glslang's line numbers are those of the original file. With
# PRELUDE (a file), its text goes between the two, as the runtime composes material shaders.
cmake_minimum_required(VERSION 3.25)

foreach(var SHADER NAME SYMBOL OUT_CPP CHECK_DIR VALIDATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "embed_shader.cmake: ${var} is not set")
  endif()
endforeach()

file(READ "${SHADER}" text)
string(REGEX MATCH "(^|\n)[ \t]*#[ \t]*version[ \t]" has_version "${text}")

set(prelude_text "")
if(PRELUDE)
  file(READ "${PRELUDE}" prelude_text)
endif()
if(has_version AND NOT PRELUDE)
  set(check_file "${SHADER}")
else()
  set(check_file "${CHECK_DIR}/${NAME}")
  get_filename_component(check_parent "${check_file}" DIRECTORY)
  file(MAKE_DIRECTORY "${check_parent}")
  file(WRITE "${check_file}" "#version 450 core\n${prelude_text}\n#line 1\n${text}")
endif()

execute_process(COMMAND "${VALIDATOR}" "${check_file}"
                RESULT_VARIABLE status OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT status EQUAL 0)
  # Report the original path, not the scratch copy, so editors can jump to the line.
  string(REPLACE "${check_file}" "${SHADER}" log "${log}")
  string(REGEX REPLACE "(ERROR|WARNING): 0:([0-9]+):" "\\1: ${SHADER}:\\2:" log "${log}")
  message(FATAL_ERROR "GLSL validation failed for ${SHADER}:\n${log}")
endif()

# Bytes rather than a raw string literal: any shader text embeds unchanged.
file(READ "${SHADER}" hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR byte_count "${hex_length} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
# Sixteen bytes a line (CMake regexes have no {n} repetition).
string(REPEAT "0x[0-9a-f][0-9a-f]," 16 line_of_bytes)
string(REGEX REPLACE "(${line_of_bytes})" "\\1\n    " bytes "${bytes}")

set(cpp "// Generated from shaders/${NAME} at build time. Do not edit.\n")
string(APPEND cpp "#include <string_view>\n\n")
string(APPEND cpp "namespace facet::driver::embedded {\n\n")
string(APPEND cpp "std::string_view ${SYMBOL}() {\n")
# unsigned char: bytes above 0x7f (UTF-8 in comments) would narrow into a signed char.
string(APPEND cpp "  static constexpr unsigned char text[] = {\n    ${bytes}0x00};\n")
string(APPEND cpp "  return {reinterpret_cast<const char*>(text), ${byte_count}};\n}\n\n")
string(APPEND cpp "}  // namespace facet::driver::embedded\n")

# Write then rename, so an interrupted step never leaves a partial source file.
file(WRITE "${OUT_CPP}.tmp" "${cpp}")
file(RENAME "${OUT_CPP}.tmp" "${OUT_CPP}")
