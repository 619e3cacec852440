# SPDX-License-Identifier: GPL-3.0-or-later
# `cmake --install build --prefix P`: the sonomap program, the libraries, their headers and a
# CMake package, so `find_package(sonomap)` gives sonomap::core, ::sim, ::audio, ::eval,
# ::support, ::formats, ::report, ::app and ::harness (all of them). See docs/sdk.md.
include(CMakePackageConfigHelpers)

set(SONOMAP_EXPORTED core sim audio eval support formats report app harness)
set(SONOMAP_EXPORTED_TARGETS)
foreach(part ${SONOMAP_EXPORTED})
  set_target_properties(sonomap_${part} PROPERTIES EXPORT_NAME ${part})
  list(APPEND SONOMAP_EXPORTED_TARGETS sonomap_${part})
endforeach()

# The libraries are shared (Debian's FindOpenVDB sets BUILD_SHARED_LIBS): installed, the
# program and each library find their siblings through a relative RUNPATH.
set_target_properties(sonomap ${SONOMAP_EXPORTED_TARGETS} PROPERTIES
  INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS sonomap RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The libraries the formats library opens on demand (harness/formats/modules.hpp).
set_target_properties(sonomap_open3d ${SONOMAP_ON_DEMAND_LIBRARIES} PROPERTIES
  INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS sonomap_open3d ${SONOMAP_ON_DEMAND_LIBRARIES} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS ${SONOMAP_EXPORTED_TARGETS} EXPORT sonomapTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
# (core/vdb_gpdf/ holds VDB-GPDF's internal stages: no public header includes them.)
foreach(dir core sim audio eval harness)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sonomap
    FILES_MATCHING PATTERN "*.hpp" PATTERN "core/vdb_gpdf" EXCLUDE)
endforeach()

set(SONOMAP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/sonomap)
install(EXPORT sonomapTargets NAMESPACE sonomap:: DESTINATION ${SONOMAP_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sonomapConfig.cmake.in
  ${PROJECT_BINARY_DIR}/sonomapConfig.cmake INSTALL_DESTINATION ${SONOMAP_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sonomapConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sonomapConfig.cmake
  ${PROJECT_BINARY_DIR}/sonomapConfigVersion.cmake DESTINATION ${SONOMAP_CMAKE_DIR})
