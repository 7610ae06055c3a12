#!/usr/bin/env bash
# Installs what the aarch64 cross build and its qemu test stage need (preset `aarch64`,
# toolchains/aarch64-linux-gnu.cmake): the cross compiler, qemu-user-static and the :arm64 multi-arch
# -dev packages of every library the product, tests and benchmarks link. Idempotent: when everything
# is present it changes nothing and needs no network. Called by scripts/install_deps.sh.
# dpkg-dev: dpkg-shlibdeps, which `cpack -G DEB` uses for the native package's Depends line.
#
# Two packages cannot be co-installed with their amd64 twins and are unpacked (dpkg-deb -x) under
# $ARM64_EXTRA instead, which the toolchain file searches:
#   libyaml-cpp-dev:arm64 (not Multi-Arch: same; its runtime libyaml-cpp0.7:arm64 installs normally),
#   iceoryx:arm64 (iox-roudi for IPC tests under qemu; /usr/bin clashes with the amd64 iox-roudi).
set -euo pipefail

ARM64_EXTRA="${ARM64_EXTRA:-/opt/orthoflow-arm64}"
PACKAGES=(
  crossbuild-essential-arm64 qemu-user-static dpkg-dev
  libtbb-dev:arm64 libxsimd-dev:arm64 libusb-1.0-0-dev:arm64 liblzf-dev:arm64 libcairo2-dev:arm64 libpng-dev:arm64
  libleveldb-dev:arm64 libyaml-cpp0.7:arm64 libcivetweb-dev:arm64 libutf8proc-dev:arm64
  libiceoryx-posh-dev:arm64 libiceoryx-hoofs-dev:arm64
  cyclonedds-dev:arm64  # the DDS bridge (bridge/); idlc runs natively (cyclonedds-tools)
  libgtest-dev:arm64 libgmock-dev:arm64 libbenchmark-dev:arm64
)
UNPACKED=(libyaml-cpp-dev:arm64 iceoryx:arm64)

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
stamp="$ARM64_EXTRA/.unpacked"
need_unpack=0
[ -f "$stamp" ] && [ "$(cat "$stamp")" = "${UNPACKED[*]}" ] || need_unpack=1
if [ ${#missing[@]} -eq 0 ] && [ "$need_unpack" -eq 0 ]; then
  echo "install_arm64_deps: all ${#PACKAGES[@]} packages present, ${#UNPACKED[@]} unpacked in $ARM64_EXTRA"
  exit 0
fi

if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  echo "install_arm64_deps: adding the arm64 architecture to dpkg"
  $SUDO dpkg --add-architecture arm64
fi
$SUDO apt-get update -qq
if [ ${#missing[@]} -gt 0 ]; then
  echo "install_arm64_deps: installing ${missing[*]}"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

echo "install_arm64_deps: unpacking ${UNPACKED[*]} into $ARM64_EXTRA"
tmp=$(mktemp -d)
chmod 755 "$tmp"  # apt's download sandbox user must be able to write here
(cd "$tmp" && apt-get download -qq "${UNPACKED[@]}")
$SUDO rm -rf "$ARM64_EXTRA"
$SUDO mkdir -p "$ARM64_EXTRA"
for deb in "$tmp"/*.deb; do $SUDO dpkg-deb -x "$deb" "$ARM64_EXTRA"; done
rm -rf "$tmp"
# The unpacked CMake config and libyaml-cpp.so name a shared library that lives in /usr, not here.
for f in libyaml-cpp.so libyaml-cpp.so.0.7.0; do
  $SUDO ln -sf /usr/lib/aarch64-linux-gnu/libyaml-cpp.so.0.7.0 "$ARM64_EXTRA/usr/lib/aarch64-linux-gnu/$f"
done
echo "${UNPACKED[*]}" | $SUDO tee "$stamp" >/dev/null
