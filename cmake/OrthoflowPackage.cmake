# Installs the exported targets and a config file so that find_package(orthoflow) works from a prefix.
# Each library is a component with its own export set (orthoflow_add_library): for
# find_package(orthoflow REQUIRED COMPONENTS kernels formats) the config file loads those, the
# components they use (in dependency order), and finds only those components' external libraries.
# Both tables (component -> components it uses, component -> external libraries) are computed here
# from the targets' link libraries, so they cannot drift from the folders' CMakeLists.txt.
include(CMakePackageConfigHelpers)

# orthoflow_package_rule(<id> LINKS <link item>... CODE <cmake code>): how a consumer's config step
# finds the external library behind <link item> (the same finds and fix-ups as OrthoflowDependencies).
# <id> is a C identifier; CODE runs in orthoflowConfig.cmake (find_dependency, _orthoflow_pkg_config).
set(ORTHOFLOW_PACKAGE_RULES "")
function(orthoflow_package_rule id)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "CODE" "LINKS")  # PARSE_ARGV: CODE keeps its ';'
  set(ORTHOFLOW_PACKAGE_RULES ${ORTHOFLOW_PACKAGE_RULES} ${id} PARENT_SCOPE)
  foreach(item IN LISTS ARG_LINKS)
    string(MAKE_C_IDENTIFIER "${item}" key)
    set(ORTHOFLOW_RULE_FOR_${key} ${id} PARENT_SCOPE)
  endforeach()
  set(ORTHOFLOW_RULE_CODE_${id} "${ARG_CODE}" PARENT_SCOPE)
endfunction()

orthoflow_package_rule(Threads LINKS Threads::Threads CODE [=[find_dependency(Threads)]=])
orthoflow_package_rule(Eigen3 LINKS Eigen3::Eigen CODE [=[find_dependency(Eigen3 3.4 NO_MODULE)]=])
orthoflow_package_rule(xsimd LINKS xsimd CODE [=[find_dependency(xsimd)
  # Debian's xsimd config adds -lxtl, which does not exist (specs/PLATFORM.md).
  set_target_properties(xsimd PROPERTIES INTERFACE_LINK_LIBRARIES "")]=])
orthoflow_package_rule(TBB LINKS TBB::tbb CODE [=[find_dependency(TBB CONFIG)]=])
orthoflow_package_rule(yaml_cpp LINKS yaml-cpp CODE [=[find_dependency(yaml-cpp)]=])
orthoflow_package_rule(nlohmann_json LINKS nlohmann_json::nlohmann_json CODE [=[find_dependency(nlohmann_json 3.10)]=])
orthoflow_package_rule(iceoryx_posh
  LINKS iceoryx_posh::iceoryx_posh iceoryx_posh::iceoryx_posh_config iceoryx_posh::iceoryx_posh_roudi
  CODE [=[find_dependency(iceoryx_posh CONFIG)]=])
orthoflow_package_rule(leveldb LINKS leveldb::leveldb CODE [=[find_dependency(Threads)
  find_dependency(leveldb CONFIG)
  # Debian 12's leveldb config links "snappy" by name; libleveldb.so already NEEDs libsnappy.so.1.
  set_target_properties(leveldb::leveldb PROPERTIES INTERFACE_LINK_LIBRARIES Threads::Threads)]=])
orthoflow_package_rule(liblzf LINKS PkgConfig::LZF CODE [=[_orthoflow_pkg_config(LZF liblzf)]=])
orthoflow_package_rule(cairo LINKS PkgConfig::CAIRO CODE [=[_orthoflow_pkg_config(CAIRO cairo)]=])
orthoflow_package_rule(libutf8proc LINKS PkgConfig::UTF8PROC CODE [=[_orthoflow_pkg_config(UTF8PROC libutf8proc)]=])
orthoflow_package_rule(libpng LINKS PkgConfig::PNG CODE [=[_orthoflow_pkg_config(PNG libpng)]=])
orthoflow_package_rule(libusb LINKS PkgConfig::LIBUSB CODE [=[_orthoflow_pkg_config(LIBUSB libusb-1.0)]=])

# orthoflow_package_links(<folder>): ORTHOFLOW_USES_<folder> (components) and ORTHOFLOW_FINDS_<folder>
# (rule ids) in the caller's scope. A static library's PRIVATE link libraries are needed when a
# consumer links it, so LINK_LIBRARIES (PUBLIC and PRIVATE) counts; an INTERFACE library has only its
# interface. A link item without a rule is an error here, not a consumer's link failure later.
function(orthoflow_package_links folder)
  get_target_property(type orthoflow_${folder} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    get_target_property(links orthoflow_${folder} INTERFACE_LINK_LIBRARIES)
  else()
    get_target_property(links orthoflow_${folder} LINK_LIBRARIES)
  endif()
  set(uses "")
  set(finds "")
  foreach(item IN LISTS links)
    if(item MATCHES "^orthoflow::(.+)$")
      if(NOT CMAKE_MATCH_1 IN_LIST ORTHOFLOW_PACKAGE_COMPONENTS)
        message(FATAL_ERROR "orthoflow_${folder} links ${item}, which is not a library of this build")
      endif()
      if(NOT CMAKE_MATCH_1 STREQUAL folder)
        list(APPEND uses ${CMAKE_MATCH_1})
      endif()
    elseif(item)
      string(MAKE_C_IDENTIFIER "${item}" key)
      if(NOT DEFINED ORTHOFLOW_RULE_FOR_${key})
        message(FATAL_ERROR "orthoflow_${folder} links '${item}': add an orthoflow_package_rule() for it in "
                            "cmake/OrthoflowPackage.cmake so that find_package(orthoflow) finds it for consumers")
      endif()
      list(APPEND finds ${ORTHOFLOW_RULE_FOR_${key}})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES uses)
  list(REMOVE_DUPLICATES finds)
  set(ORTHOFLOW_USES_${folder} ${uses} PARENT_SCOPE)
  set(ORTHOFLOW_FINDS_${folder} ${finds} PARENT_SCOPE)
endfunction()

# orthoflow_package_order(<out>): the components, each after the components it uses (whatever the
# add_subdirectory order); a cycle is an error.
function(orthoflow_package_order out)
  set(order "")
  set(pending ${ORTHOFLOW_PACKAGE_COMPONENTS})
  while(pending)
    set(ready "")
    foreach(folder IN LISTS pending)
      set(missing ${ORTHOFLOW_USES_${folder}})
      list(REMOVE_ITEM missing ${order})
      if(NOT missing)
        list(APPEND ready ${folder})
      endif()
    endforeach()
    if(NOT ready)
      message(FATAL_ERROR "orthoflow libraries use each other in a cycle: ${pending}")
    endif()
    list(APPEND order ${ready})
    list(REMOVE_ITEM pending ${ready})
  endwhile()
  set(${out} ${order} PARENT_SCOPE)
endfunction()

# orthoflow_package_config_code(): ORTHOFLOW_PACKAGE_TABLE (the components in order, what each uses
# and finds) and ORTHOFLOW_PACKAGE_FINDS (each rule's code, guarded by its flag) for the config file.
function(orthoflow_package_config_code)
  list(JOIN ORTHOFLOW_PACKAGE_ORDER " " order)
  set(table "set(_orthoflow_components ${order})\n")
  set(used "")
  foreach(folder IN LISTS ORTHOFLOW_PACKAGE_ORDER)
    list(JOIN ORTHOFLOW_USES_${folder} " " uses)
    list(JOIN ORTHOFLOW_FINDS_${folder} " " finds)
    string(APPEND table "set(_orthoflow_uses_${folder} ${uses})\nset(_orthoflow_finds_${folder} ${finds})\n")
    list(APPEND used ${ORTHOFLOW_FINDS_${folder}})
  endforeach()
  set(externals "")
  set(code "")
  foreach(id IN LISTS ORTHOFLOW_PACKAGE_RULES)
    if(id IN_LIST used)
      list(APPEND externals ${id})
      string(APPEND code "if(_orthoflow_find_${id})\n  ${ORTHOFLOW_RULE_CODE_${id}}\nendif()\n")
    endif()
  endforeach()
  list(JOIN externals " " externals)
  string(APPEND table "set(_orthoflow_externals ${externals})")
  set(ORTHOFLOW_PACKAGE_TABLE "${table}" PARENT_SCOPE)
  set(ORTHOFLOW_PACKAGE_FINDS "${code}" PARENT_SCOPE)
endfunction()

get_property(ORTHOFLOW_PACKAGE_COMPONENTS GLOBAL PROPERTY ORTHOFLOW_LIBRARY_FOLDERS)
foreach(ORTHOFLOW_FOLDER IN LISTS ORTHOFLOW_PACKAGE_COMPONENTS)
  orthoflow_package_links(${ORTHOFLOW_FOLDER})
endforeach()
orthoflow_package_order(ORTHOFLOW_PACKAGE_ORDER)
orthoflow_package_config_code()

foreach(ORTHOFLOW_FOLDER IN LISTS ORTHOFLOW_PACKAGE_ORDER)
  install(EXPORT orthoflow_${ORTHOFLOW_FOLDER}Targets NAMESPACE orthoflow::
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/orthoflow)
endforeach()
# The orthoflow CLI (apps/CMakeLists.txt): an imported executable, with no link dependencies.
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
install(FILES ${PROJECT_SOURCE_DIR}/deploy/orthoflow.service ${PROJECT_SOURCE_DIR}/deploy/60-orthoflow-kinect.rules
  ${PROJECT_SOURCE_DIR}/deploy/60-orthoflow-jaco.rules
  DESTINATION ${CMAKE_INSTALL_DATADIR}/orthoflow/deploy)

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
    "libc6 (>= 2.35), libstdc++6 (>= 12), libgcc-s1 (>= 3.0), libtbb12 (>= 2021.4.0), libyaml-cpp0.7 (>= 0.7.0), libcairo2 (>= 1.2.4), libpng16-16 (>= 1.6.2), libcivetweb1 (>= 1.15), liblzf1 (>= 1.5), libleveldb1d (>= 1.23), libiceoryx-hoofs2 (>= 2.0.3+dfsg), libiceoryx-posh2 (>= 2.0.3+dfsg), libiceoryx-posh-config2 (>= 2.0.3+dfsg), libiceoryx-posh-roudi2 (>= 2.0.3+dfsg), libusb-1.0-0 (>= 2:1.0.26), libutf8proc2 (>= 2.1)")
  if(TARGET orthoflow_bridge)  # the DDS bridge links Cyclone DDS (bridge/CMakeLists.txt)
    string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS ", libddsc0debian (>= 0.10.2)")
  endif()
else()
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
endif()
include(CPack)
