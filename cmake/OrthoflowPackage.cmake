# Installs the exported targets and a config file so that find_package(orthoflow) works from a prefix.
include(CMakePackageConfigHelpers)
install(EXPORT orthoflowTargets NAMESPACE orthoflow:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/orthoflow)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/orthoflowConfig.cmake.in
  ${PROJECT_BINARY_DIR}/orthoflowConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/orthoflow)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/orthoflowConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/orthoflowConfig.cmake ${PROJECT_BINARY_DIR}/orthoflowConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/orthoflow)
