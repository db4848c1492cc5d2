# Install rules: the libraries (fogcl, + fogcl_io when built), public headers, the CLI, a CMake
# package (find_package(fogcl [COMPONENTS io])), pkg-config files (fogcl, fogcl-io) and the
# examples. Kernels are embedded in the library, so nothing from kernels/ is installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FOGCL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/fogcl)
# One export file per component: fogclConfig.cmake reads the io one only when io is asked for.
install(TARGETS fogcl EXPORT fogclTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT fogclTargets NAMESPACE fogcl:: DESTINATION ${FOGCL_CMAKE_DIR})
if(FOGCL_BUILD_IO)
  install(TARGETS fogcl_io EXPORT fogclIoTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
          FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT fogclIoTargets NAMESPACE fogcl:: DESTINATION ${FOGCL_CMAKE_DIR})
endif()
if(FOGCL_BUILD_CLI)
  install(TARGETS fogcl_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

get_target_property(fogcl_type fogcl TYPE)
if(fogcl_type STREQUAL "STATIC_LIBRARY")
  set(FOGCL_STATIC ON)  # private dependencies (Imath; OpenEXR, libpng) are then needed at link time
else()
  set(FOGCL_STATIC OFF)
endif()
set(FOGCL_HAS_IO ${FOGCL_BUILD_IO})
configure_package_config_file(cmake/fogclConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/fogclConfig.cmake
                              INSTALL_DESTINATION ${FOGCL_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/fogclConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fogclConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/fogclConfigVersion.cmake
        DESTINATION ${FOGCL_CMAKE_DIR})

# pkg-config: fogcl, and fogcl-io (which requires fogcl). The private dependencies are listed for
# `pkg-config --static` only, which a static build needs.
# Relocatable: the prefix is found from the .pc file's own folder (cmake --install --prefix works).
string(REGEX REPLACE "[^/]+" ".." FOGCL_PC_UP "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
if(FOGCL_STATIC)
  set(FOGCL_PC_REQUIRES_PRIVATE "Imath")
else()
  set(FOGCL_PC_REQUIRES_PRIVATE "")
endif()
set(FOGCL_PC_NAME fogcl)
set(FOGCL_PC_DESCRIPTION "Deferred fog and fog volumes as OpenCL kernels, with a C++17 host library")
set(FOGCL_PC_REQUIRES "OpenCL glm")
set(FOGCL_PC_LIB fogcl)
configure_file(cmake/fogcl.pc.in ${CMAKE_CURRENT_BINARY_DIR}/fogcl.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fogcl.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(FOGCL_BUILD_IO)
  if(FOGCL_STATIC)
    set(FOGCL_PC_REQUIRES_PRIVATE "OpenEXR libpng")
  endif()
  set(FOGCL_PC_NAME fogcl-io)
  set(FOGCL_PC_DESCRIPTION "fogcl's image files: OpenEXR in and out, PNG previews")
  set(FOGCL_PC_REQUIRES "fogcl = ${PROJECT_VERSION}")
  set(FOGCL_PC_LIB fogcl_io)
  configure_file(cmake/fogcl.pc.in ${CMAKE_CURRENT_BINARY_DIR}/fogcl-io.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fogcl-io.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()

install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The programs docs/library.md walks through, to copy from (built against an install by the tests).
install(DIRECTORY examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
