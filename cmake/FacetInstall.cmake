# `cmake --install build --prefix P`: the libraries (static), their headers, the CMake package
# (find_package(facet CONFIG): facet::facet, facet::driver, facet::interop, facet::projection,
# facet::projection_io) and pkg-config's facet.pc. Shaders are compiled into facet::driver, so
# nothing is read from the install at run time.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

if(NOT TARGET facet_api)
  return()  # the API needs the driver and interop (FACET_BUILD_DRIVER, FACET_BUILD_INTEROP)
endif()

# facet_warnings is linked privately; static libraries carry it as a link-only, empty target.
set_target_properties(facet_projection PROPERTIES EXPORT_NAME projection)
set_target_properties(facet_projection_io PROPERTIES EXPORT_NAME projection_io)
set_target_properties(facet_driver PROPERTIES EXPORT_NAME driver)
set_target_properties(facet_interop PROPERTIES EXPORT_NAME interop)
set_target_properties(facet_warnings PROPERTIES EXPORT_NAME warnings)
install(TARGETS facet_api facet_driver facet_interop facet_projection facet_projection_io
                facet_warnings
        EXPORT facetTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# facet/driver/capture.hpp belongs to facet::capture, which is not installed.
foreach(dir api/include driver/include interop/include projection/include projection/io/include)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          PATTERN capture.hpp EXCLUDE)
endforeach()

# The GLSL interface a material shader is written against (Display::set_material_shader).
install(FILES ${PROJECT_SOURCE_DIR}/shaders/scene/material_interface.frag
        DESTINATION ${CMAKE_INSTALL_DATADIR}/facet)

set(FACET_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/facet)
install(EXPORT facetTargets NAMESPACE facet:: DESTINATION ${FACET_CMAKE_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/facetConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/facetConfig.cmake
                              INSTALL_DESTINATION ${FACET_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/facetConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/facetConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/facetConfigVersion.cmake
        DESTINATION ${FACET_CMAKE_DIR})

# The .pc finds the prefix from its own folder, so the install can move.
file(RELATIVE_PATH FACET_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${CMAKE_CURRENT_LIST_DIR}/facet.pc.in ${CMAKE_CURRENT_BINARY_DIR}/facet.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/facet.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
