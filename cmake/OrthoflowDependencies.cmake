# Every dependency is a Debian 12 package (scripts/install_deps.sh installs them).
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(xsimd REQUIRED)
# Debian's xsimd config adds -lxtl, which does not exist (specs/PLATFORM.md).
set_target_properties(xsimd PROPERTIES INTERFACE_LINK_LIBRARIES "")
find_package(TBB CONFIG REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(iceoryx_posh CONFIG REQUIRED)  # pulls iceoryx_hoofs; C++ standard set per target
find_package(leveldb CONFIG REQUIRED)
# Debian 12's leveldb config links "snappy" by name, which needs libsnappy-dev; libleveldb.so already NEEDs libsnappy.so.1.
set_target_properties(leveldb::leveldb PROPERTIES INTERFACE_LINK_LIBRARIES Threads::Threads)
find_package(PkgConfig REQUIRED)
pkg_check_modules(LZF REQUIRED IMPORTED_TARGET liblzf)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)
pkg_check_modules(UTF8PROC REQUIRED IMPORTED_TARGET libutf8proc)  # labels: NFC and invisible characters (core/label_text.cpp)
pkg_check_modules(PNG REQUIRED IMPORTED_TARGET libpng)  # the web view's camera image (ui/png_encode.cpp), TUM depth PNGs (formats/png_depth.cpp)

if(BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
if(ORTHOFLOW_WITH_PCL AND (BUILD_TESTS OR BUILD_BENCHMARKS))
  # PCL is a reference for tests and benchmarks only: never linked into the product.
  # Debian's PCL config pulls VTK, whose exported targets name MPI::MPI_C: find MPI first.
  enable_language(C)
  find_package(MPI QUIET COMPONENTS C)
  find_package(PCL 1.13 QUIET COMPONENTS common io filters sample_consensus segmentation surface search kdtree features)
  if(PCL_FOUND)
    message(STATUS "PCL ${PCL_VERSION} found: reference cross-checks enabled")
  else()
    message(STATUS "PCL not found: reference cross-checks disabled")
  endif()
endif()
