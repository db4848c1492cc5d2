# Install rules: the library (+ fogcl::io when built), public headers, the CLI, a CMake package
# (find_package(fogcl [COMPONENTS io])) and a pkg-config file. Kernels are embedded in the
# library, so nothing from kernels/ is installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FOGCL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/fogcl)
set(fogcl_install_targets fogcl)
if(FOGCL_BUILD_IO)
  list(APPEND fogcl_install_targets fogcl_io)
endif()
install(TARGETS ${fogcl_install_targets} EXPORT fogclTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT fogclTargets NAMESPACE fogcl:: DESTINATION ${FOGCL_CMAKE_DIR})
if(FOGCL_BUILD_CLI)
  install(TARGETS fogcl_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

get_target_property(fogcl_type fogcl TYPE)
if(fogcl_type STREQUAL "STATIC_LIBRARY")
  set(FOGCL_STATIC ON)  # private dependencies (Imath) are then needed at link time
else()
  set(FOGCL_STATIC OFF)
endif()
configure_package_config_file(cmake/fogclConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/fogclConfig.cmake
                              INSTALL_DESTINATION ${FOGCL_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/fogclConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fogclConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/fogclConfigVersion.cmake
        DESTINATION ${FOGCL_CMAKE_DIR})

# pkg-config: core only (fogcl::io's users go through CMake). Static builds list Imath as private.
if(FOGCL_STATIC)
  set(FOGCL_PC_REQUIRES_PRIVATE "Imath")
else()
  set(FOGCL_PC_REQUIRES_PRIVATE "")
endif()
# Relocatable: the prefix is found from the .pc file's own folder (cmake --install --prefix works).
string(REGEX REPLACE "[^/]+" ".." FOGCL_PC_UP "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
configure_file(cmake/fogcl.pc.in ${CMAKE_CURRENT_BINARY_DIR}/fogcl.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fogcl.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/fogcl)
