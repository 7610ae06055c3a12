# Per-target settings (STYLE rule 14): no global flags, never force CMAKE_BUILD_TYPE.
set(ORTHOFLOW_SHARED_DIR "${PROJECT_SOURCE_DIR}/../shared" CACHE PATH "The shared data folder beside the checkout")

# orthoflow_target_defaults(tgt): C++20 and warnings as errors on our own code.
function(orthoflow_target_defaults tgt)
  target_compile_features(${tgt} PUBLIC cxx_std_20)
  set_target_properties(${tgt} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
  target_compile_options(${tgt} PRIVATE -Wall -Wextra -Wconversion -Wshadow -Werror)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    # GCC 12 at -O3 reports -Wrestrict inside libstdc++'s std::string concatenation (GCC bug 105651).
    target_compile_options(${tgt} PRIVATE -Wno-restrict)
  endif()
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64|ARM64)$")
    # Same results as x86-64: no fused multiply-add contraction of scalar code (toolchains/README.md);
    # also for native builds on an ARM board, which do not use the cross toolchain file.
    target_compile_options(${tgt} PRIVATE -ffp-contract=off)
  endif()
endfunction()

# orthoflow_add_library(folder SOURCES ... [PUBLIC_LIBS ...] [PRIVATE_LIBS ...])
# One library per top-level folder, aliased orthoflow::<folder>, installed and exported as the
# package component <folder>.
function(orthoflow_add_library folder)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LIBS;PRIVATE_LIBS" ${ARGN})
  set(tgt orthoflow_${folder})
  if(ARG_SOURCES)
    add_library(${tgt} STATIC ${ARG_SOURCES})
    orthoflow_target_defaults(${tgt})
    target_include_directories(${tgt} PUBLIC
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/orthoflow>)
    target_link_libraries(${tgt} PUBLIC ${ARG_PUBLIC_LIBS} PRIVATE ${ARG_PRIVATE_LIBS})
  else()
    add_library(${tgt} INTERFACE)
    target_compile_features(${tgt} INTERFACE cxx_std_20)
    target_include_directories(${tgt} INTERFACE
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/orthoflow>)
    target_link_libraries(${tgt} INTERFACE ${ARG_PUBLIC_LIBS})
  endif()
  set_target_properties(${tgt} PROPERTIES EXPORT_NAME ${folder})
  add_library(orthoflow::${folder} ALIAS ${tgt})
  # One export set per library: the package component `folder` (cmake/OrthoflowPackage.cmake).
  install(TARGETS ${tgt} EXPORT orthoflow_${folder}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  set_property(GLOBAL APPEND PROPERTY ORTHOFLOW_LIBRARY_FOLDERS ${folder})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/orthoflow/${folder}
    FILES_MATCHING PATTERN "*.hpp" PATTERN "*.inl")
endfunction()
