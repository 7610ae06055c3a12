#!/usr/bin/env bash
# Installs every build and test dependency from Debian 12 packages. Non-interactive and idempotent:
# when everything is already installed it changes nothing and needs no network.
set -euo pipefail

PACKAGES=(
  cmake ninja-build g++ pkg-config git
  ccache  # scripts/test.sh: the four presets' builds reuse what an earlier build compiled
  libeigen3-dev libxsimd-dev libtbb-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  liblzf-dev libcairo2-dev libpng-dev libleveldb-dev libusb-1.0-0-dev libutf8proc-dev
  libcivetweb-dev  # the web view's HTTP + WebSocket server (ui/, `orthoflow run --ui`)
  iceoryx libiceoryx-posh-dev libiceoryx-hoofs-dev
  cyclonedds-dev cyclonedds-tools  # the DDS bridge (bridge/, issue 23): libddsc and idlc
  nftables  # test-only: packet loss and a partition between two network namespaces (tests/bridge)
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev clang-format-14
  libpcl-dev
  libfreenect-dev libfreenect-bin  # test-only: libfreenect against the simulated Kinect (tests/support/sim_libusb)
  chromium chromium-driver  # test-only: the web view in a real, headless browser (tests/ui/check_browser.py)
  # The robot image (scripts/build_image.sh, issue 24): Debian's tools to build it, qemu to boot it.
  mmdebstrap arch-test qemu-user-static e2fsprogs dosfstools mtools fdisk zstd grub-efi-amd64-bin grub-efi-arm64-bin:arm64
  qemu-system-x86 qemu-system-arm ovmf qemu-efi-aarch64 curl  # test-only: booting the images (scripts/test_image.sh)
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
else
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "install_deps: installing ${missing[*]}"
  # grub-efi-arm64-bin exists only as an arm64 package: dpkg must know the architecture first (on a
  # fresh Debian 12 machine it does not; install_arm64_deps.sh below needs it too).
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    echo "install_deps: adding the arm64 architecture to dpkg"
    $SUDO dpkg --add-architecture arm64
  fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# The aarch64 cross build and its qemu test stage (preset aarch64): cross compiler, qemu, :arm64 libraries.
bash "$(dirname "$0")/install_arm64_deps.sh"
