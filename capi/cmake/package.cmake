# How other projects find libsogmm: `cmake --install <build> --prefix <P>`
# (component sogmm_capi) installs the header, libsogmm.so and libsogmm.a, a
# CMake package (find_package(sogmm) -> sogmm::sogmm) and sogmm.pc. The build
# tree gets the same two files, pointing at the build: <build>/capi is both a
# sogmm_DIR and a PKG_CONFIG_PATH entry.
#
# Both carry an rpath to the library's folder (sogmmConfig.cmake.in,
# sogmm.pc.in), so a program built against either runs without
# LD_LIBRARY_PATH, also after the program itself is installed.
install(TARGETS sogmm EXPORT sogmmTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT sogmm_capi
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT sogmm_capi
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT sogmm_capi
  PUBLIC_HEADER DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sogmm COMPONENT sogmm_capi)
install(FILES ${SOGMM_STATIC_ARCHIVE} DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT sogmm_capi)

# ---- CMake package ----
set(SOGMM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/sogmm)
set(install_files ${CMAKE_CURRENT_BINARY_DIR}/install-files)
install(EXPORT sogmmTargets NAMESPACE sogmm:: DESTINATION ${SOGMM_CMAKE_DIR} COMPONENT sogmm_capi)
export(EXPORT sogmmTargets NAMESPACE sogmm:: FILE ${CMAKE_CURRENT_BINARY_DIR}/sogmmTargets.cmake)
# SOGMM_CONFIG_TO_LIBDIR: from the config file's folder to the library's.
file(RELATIVE_PATH SOGMM_CONFIG_TO_LIBDIR "/${SOGMM_CMAKE_DIR}" "/${CMAKE_INSTALL_LIBDIR}")
configure_package_config_file(sogmmConfig.cmake.in ${install_files}/sogmmConfig.cmake
  INSTALL_DESTINATION ${SOGMM_CMAKE_DIR})
set(SOGMM_CONFIG_TO_LIBDIR .)
configure_package_config_file(sogmmConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/sogmmConfig.cmake
  INSTALL_DESTINATION ${CMAKE_CURRENT_BINARY_DIR} INSTALL_PREFIX ${CMAKE_CURRENT_BINARY_DIR})
# Same major version = compatible (the ABI version guards the binary level).
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/sogmmConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${install_files}/sogmmConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/sogmmConfigVersion.cmake
  DESTINATION ${SOGMM_CMAKE_DIR} COMPONENT sogmm_capi)

# ---- pkg-config ----
# Installed: relocatable (the prefix is found from the .pc file's own
# location) unless the install dirs are absolute.
file(RELATIVE_PATH SOGMM_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" SOGMM_PC_TO_PREFIX "${SOGMM_PC_TO_PREFIX}")
set(SOGMM_PC_PREFIX "\${pcfiledir}/${SOGMM_PC_TO_PREFIX}")
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(SOGMM_PC_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
else()
  set(SOGMM_PC_LIBDIR "\${exec_prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(SOGMM_PC_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
else()
  set(SOGMM_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
configure_file(sogmm.pc.in ${install_files}/sogmm.pc @ONLY)
install(FILES ${install_files}/sogmm.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
  COMPONENT sogmm_capi)
# Build tree: the library here, the header in the source tree.
set(SOGMM_PC_PREFIX ${CMAKE_CURRENT_BINARY_DIR})
set(SOGMM_PC_LIBDIR ${CMAKE_CURRENT_BINARY_DIR})
set(SOGMM_PC_INCLUDEDIR ${CMAKE_CURRENT_SOURCE_DIR}/include)
configure_file(sogmm.pc.in ${CMAKE_CURRENT_BINARY_DIR}/sogmm.pc @ONLY)
