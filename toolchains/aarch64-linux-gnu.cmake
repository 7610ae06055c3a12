# Cross-compiles orthoflow for 64-bit ARM Linux (Debian arm64: Jetson, Raspberry Pi 4/5, i.MX8) with
# Debian's crossbuild-essential-arm64, linking the :arm64 multi-arch packages that
# scripts/install_arm64_deps.sh installs. Tests and tools run through qemu-aarch64-static
# (binfmt_misc is not mounted on the build machines, so CMake prefixes every target command).
# Recipe and pitfalls: shared specs/PLATFORM.md "Cross-compiling to aarch64"; docs/DEPLOY.md.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# GCC contracts a*b+c into one fused multiply-add by default (-ffp-contract=fast), and every aarch64
# CPU has FMA, while the x86-64 baseline has none: the same scalar code then rounds differently on the
# two (measured: a table depth of make_scene(seed 42) one ulp off, convex hull points outside their hull).
# Off, the scalar references round as on x86-64; the NEON kernels still fuse where they call xsimd::fma.
set(CMAKE_C_FLAGS_INIT "-ffp-contract=off")
set(CMAKE_CXX_FLAGS_INIT "-ffp-contract=off")
# Multi-arch layout: libraries and CMake/pkg-config files live under /usr/lib/aarch64-linux-gnu.
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
# libyaml-cpp-dev is not co-installable for two architectures: install_arm64_deps.sh unpacks the arm64
# one here (headers, CMake config, libyaml-cpp.so pointing at the installed libyaml-cpp0.7:arm64).
set(ORTHOFLOW_ARM64_EXTRA "/opt/orthoflow-arm64" CACHE PATH "Unpacked arm64 packages that cannot be co-installed")
list(APPEND CMAKE_PREFIX_PATH "${ORTHOFLOW_ARM64_EXTRA}/usr")
# Never pass -L /usr/aarch64-linux-gnu to qemu: with :arm64 packages installed the loader in
# /lib/ld-linux-aarch64.so.1 and the cross libc would mix (TBB programs then spin forever).
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/bin/qemu-aarch64-static)
# Programs (pkg-config, qemu, sh) are the build machine's; nothing else is searched outside the target.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
# CLI tests that pass a target's path to `sh -c` run it through the emulator too.
set(CMAKE_PROJECT_INCLUDE "${CMAKE_CURRENT_LIST_DIR}/../cmake/OrthoflowCrossTesting.cmake")
