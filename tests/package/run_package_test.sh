#!/usr/bin/env bash
# usage: run_package_test.sh BUILD_DIR SCRATCH_DIR PACKAGE_TEST_DIR CXX CXXFLAGS LDFLAGS
# Installs BUILD_DIR into a scratch prefix and builds consumers against it with find_package(orthoflow):
#  - consumer/: no COMPONENTS (everything loaded); links kernels+formats, and every library in consumer_full;
#  - consumer_components/: COMPONENTS kernels formats, configured where TBB, iceoryx, LevelDB, yaml-cpp
#    and nlohmann_json cannot be found (CMAKE_DISABLE_FIND_PACKAGE_*) and pkg-config knows only liblzf
#    and libpng (formats' private dependencies) and libutf8proc (core's; no cairo, no libusb);
#  - controls: under those restrictions consumer/ must fail (on TBB), and consumer_components/ must
#    fail once liblzf is hidden too (formats' private dependency is looked for): the restrictions bite.
set -euo pipefail
build=$1 scratch=$2 tests=$3 cxx=$4 cxxflags=$5 ldflags=$6
rm -rf "$scratch"
mkdir -p "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" >"$scratch/install.log"

# configure NAME SOURCE [ARGS...]: the consumer's configure step, its log in $scratch/NAME.log.
configure() {
  local name=$1 source=$2
  shift 2
  cmake -S "$source" -B "$scratch/$name" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_CXX_COMPILER="$cxx" \
    -DCMAKE_CXX_FLAGS="$cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" "$@" >"$scratch/$name.log" 2>&1
}
# expect_failure NAME NEEDLE SOURCE [ARGS...]: the configure step fails and its log names NEEDLE.
expect_failure() {
  local name=$1 needle=$2
  shift 2
  if configure "$name" "$@"; then
    echo "package: $name: configured, but it should have failed" >&2
    exit 1
  fi
  if ! tr -s ' \n' ' ' <"$scratch/$name.log" | grep -qF "$needle"; then  # CMake wraps its messages
    echo "package: $name: failed without naming '$needle':" >&2
    cat "$scratch/$name.log" >&2
    exit 1
  fi
  echo "package: $name: fails as it should ($needle)"
}

configure full "$tests/consumer" || { cat "$scratch/full.log" >&2; exit 1; }
cmake --build "$scratch/full" >"$scratch/full.build.log" || { cat "$scratch/full.build.log" >&2; exit 1; }
"$scratch/full/consumer"
"$scratch/full/consumer_full"

# Only liblzf, libpng (with the zlib its .pc requires) and libutf8proc are visible to pkg-config; the
# CMake packages of the heavy dependencies are disabled. The last control sees libutf8proc alone.
pc_only_lzf="$scratch/pkgconfig_lzf" pc_none="$scratch/pkgconfig_none"
mkdir -p "$pc_only_lzf" "$pc_none"
cp "$(pkg-config --variable=pcfiledir liblzf)/liblzf.pc" "$pc_only_lzf/"
cp -L "$(pkg-config --variable=pcfiledir libpng)/libpng.pc" "$pc_only_lzf/libpng.pc"
cp "$(pkg-config --variable=pcfiledir zlib)/zlib.pc" "$pc_only_lzf/"
cp "$(pkg-config --variable=pcfiledir libutf8proc)/libutf8proc.pc" "$pc_only_lzf/"
cp "$(pkg-config --variable=pcfiledir libutf8proc)/libutf8proc.pc" "$pc_none/"
restricted=(-DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON -DCMAKE_DISABLE_FIND_PACKAGE_iceoryx_posh=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_iceoryx_hoofs=ON -DCMAKE_DISABLE_FIND_PACKAGE_leveldb=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_yaml-cpp=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON)
export PKG_CONFIG_PATH=""
PKG_CONFIG_LIBDIR="$pc_only_lzf" configure components "$tests/consumer_components" "${restricted[@]}" ||
  { cat "$scratch/components.log" >&2; exit 1; }
cmake --build "$scratch/components" >"$scratch/components.build.log" ||
  { cat "$scratch/components.build.log" >&2; exit 1; }
# CMake lists the manually set variables nobody read: find_package never ran for these packages.
for package in TBB iceoryx_posh iceoryx_hoofs leveldb yaml-cpp nlohmann_json; do
  if ! sed -n '/not used by the project/,$p' "$scratch/components.log" | grep -qx "  *CMAKE_DISABLE_FIND_PACKAGE_$package"; then
    echo "package: COMPONENTS kernels formats looked for $package:" >&2
    cat "$scratch/components.log" >&2
    exit 1
  fi
done
echo "package: COMPONENTS kernels formats: configured and linked without TBB, iceoryx, LevelDB, yaml-cpp, cairo"
"$scratch/components/consumer"

PKG_CONFIG_LIBDIR="$pc_only_lzf" expect_failure control_full "CMAKE_DISABLE_FIND_PACKAGE_TBB" \
  "$tests/consumer" "${restricted[@]}"
PKG_CONFIG_LIBDIR="$pc_none" expect_failure control_no_lzf "pkg-config module liblzf could not be found" \
  "$tests/consumer_components" "${restricted[@]}"
echo "package: all consumers ok"
