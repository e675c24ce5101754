# Installs facet into SCRATCH/prefix, builds every example of SOURCE_DIR/examples out of tree
# against it (find_package(facet CONFIG) through facet_DIR), runs each headless and checks that
# it wrote its PNGs; then builds the orbiting-planets example with pkg-config's facet.pc alone.
# Run by ctest (tests/api/CMakeLists.txt); SCRATCH is removed at the start and on success.
foreach(var BUILD_DIR SOURCE_DIR SCRATCH GENERATOR CXX)
  if(NOT ${var})
    message(FATAL_ERROR "examples_out_of_tree.cmake: -D${var}= is required")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "${command}\nfailed (${status}):\n${out}")
  endif()
  message(STATUS "ok: ${ARGV0} ${ARGV1} ${ARGV2}")
endfunction()

file(REMOVE_RECURSE ${SCRATCH})
set(prefix ${SCRATCH}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
set(launcher)
if(CCACHE)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CCACHE})
endif()

foreach(example orbiting_planets own_perspective)
  set(build ${SCRATCH}/${example})
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/${example} -B ${build} -G ${GENERATOR}
      -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -Dfacet_DIR=${prefix}/lib/cmake/facet
      ${launcher})
  run(${CMAKE_COMMAND} --build ${build})
endforeach()
run(${SCRATCH}/orbiting_planets/orbiting_planets --headless --frames 3 --size 128 --out
    ${SCRATCH}/out_a)
run(${SCRATCH}/own_perspective/own_perspective --frames 1 --out ${SCRATCH}/out_b)
file(GLOB pngs_a ${SCRATCH}/out_a/*.png)
file(GLOB pngs_b ${SCRATCH}/out_b/*.png)
list(LENGTH pngs_a count_a)
list(LENGTH pngs_b count_b)
if(NOT count_a EQUAL 3 OR NOT count_b EQUAL 4)
  message(FATAL_ERROR "expected 3 PNGs from orbiting_planets and 4 from own_perspective, got "
                      "${count_a} and ${count_b}")
endif()

# pkg-config alone: compile and link example (a) with the installed facet.pc.
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs facet OUTPUT_VARIABLE flags
                RESULT_VARIABLE status OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "pkg-config facet failed")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
run(${CCACHE} ${CXX} -std=c++20 -O1 ${SOURCE_DIR}/examples/orbiting_planets/main.cpp -o
    ${SCRATCH}/orbiting_planets_pc ${flags})
run(${SCRATCH}/orbiting_planets_pc --headless --frames 1 --size 64 --out ${SCRATCH}/out_pc)
file(REMOVE_RECURSE ${SCRATCH})
