#!/usr/bin/env bash
# usage: run_package_test.sh BUILD_DIR SCRATCH_DIR CONSUMER_SRC CXX CXXFLAGS LDFLAGS
set -euo pipefail
build=$1 scratch=$2 consumer=$3 cxx=$4 cxxflags=$5 ldflags=$6
rm -rf "$scratch"
mkdir -p "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" >"$scratch/install.log"
cmake -S "$consumer" -B "$scratch/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_CXX_FLAGS="$cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >"$scratch/configure.log"
cmake --build "$scratch/build" >"$scratch/build.log"
"$scratch/build/consumer"
