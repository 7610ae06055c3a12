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

# Deployment (issue 10, docs/DEPLOY.md): graph files and the systemd unit example, then a Debian package.
# `cpack -G DEB` in a build tree writes orthoflow_<version>_<arch>.deb: amd64 natively, arm64 from the
# aarch64 preset. Native builds compute the Depends line with dpkg-shlibdeps; the cross build cannot
# (dpkg-shlibdeps reads the host's amd64 database), so it lists the Debian 12 runtime packages of every
# shared library the orthoflow binary links (readelf -d apps/orthoflow; check it when a library is added).
file(GLOB ORTHOFLOW_GRAPH_FILES ${PROJECT_SOURCE_DIR}/graphs/*.yaml)
install(FILES ${ORTHOFLOW_GRAPH_FILES} DESTINATION ${CMAKE_INSTALL_DATADIR}/orthoflow/graphs)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/orthoflow.service DESTINATION ${CMAKE_INSTALL_DATADIR}/orthoflow/deploy)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME orthoflow)
set(CPACK_PACKAGE_VENDOR orthoflow)
set(CPACK_PACKAGE_CONTACT "orthoflow maintainers <orthoflow@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}: the orthoflow CLI, graph files, static libraries and headers")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # orthoflow_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "iceoryx")
set(CPACK_STRIP_FILES ON)
if(CMAKE_CROSSCOMPILING)
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.35), libstdc++6 (>= 12), libgcc-s1 (>= 3.0), libtbb12 (>= 2021.4.0), libyaml-cpp0.7 (>= 0.7.0), libcairo2 (>= 1.2.4), liblzf1 (>= 1.5), libleveldb1d (>= 1.23), libiceoryx-hoofs2 (>= 2.0.3+dfsg), libiceoryx-posh2 (>= 2.0.3+dfsg), libiceoryx-posh-config2 (>= 2.0.3+dfsg), libiceoryx-posh-roudi2 (>= 2.0.3+dfsg)")
else()
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
endif()
include(CPack)
