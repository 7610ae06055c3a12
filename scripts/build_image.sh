#!/usr/bin/env bash
# Builds a flashable robot image with orthoflow (issue 24, docs/DEPLOY.md), from Debian 12's archive
# with Debian's own tools, for amd64 or arm64:
#   DIR/orthoflow-ARCH.img              raw GPT disk: EFI boot loader, read-only root, data partition
#   DIR/orthoflow-rootfs-ARCH.tar.zst   the root file system, for boards with their own boot loader
#   DIR/packages-ARCH.txt               every installed package and version (the image's pinned list)
#   DIR/vmlinuz-ARCH, DIR/initrd-ARCH.img, DIR/cmdline-ARCH   the kernel, to boot it directly (tests)
#   DIR/build-ARCH.txt                  what was built from what, sizes and times
#   DIR/mmdebstrap-ARCH.log             the root file system's build, each line with its second
#
# usage: scripts/build_image.sh --arch amd64|arm64 --out DIR [--config robot.yaml] [--deb FILE]
#                               [--orthoflow BIN] [--mirror URL] [--lock packages.txt]
#   --config   the robot's configuration (default deploy/image/robot.yaml; docs/DEPLOY.md lists keys)
#   --deb      the orthoflow package (default: build/release/deb or build/aarch64/deb, made by cpack)
#   --orthoflow  an orthoflow binary for this machine, to check and render the configuration
#              (default build/release/apps/orthoflow, else the one on PATH)
#   --mirror   the Debian mirror (default: http://deb.debian.org/debian)
#   --lock     fail unless the image's package list equals this file (a previous packages-ARCH.txt)
#
# Needs root (mmdebstrap's root mode: correct owners in the image), mmdebstrap, e2fsprogs, dosfstools,
# mtools, fdisk, grub-efi-{amd64,arm64}-bin, zstd; for a foreign architecture, qemu-user-static with
# binfmt_misc (registered here when missing). scripts/install_deps.sh installs them all.
set -euo pipefail

here=$(cd "$(dirname "$0")/.." && pwd)
arch="" out="" config="$here/deploy/image/robot.yaml" deb="" orthoflow="" lock=""
mirror="http://deb.debian.org/debian"
die() { echo "build_image: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) arch="${2:-}"; shift 2 ;;
    --out) out="${2:-}"; shift 2 ;;
    --config) config="${2:-}"; shift 2 ;;
    --deb) deb="${2:-}"; shift 2 ;;
    --orthoflow) orthoflow="${2:-}"; shift 2 ;;
    --mirror) mirror="${2:-}"; shift 2 ;;
    --lock) lock="${2:-}"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) die "unknown argument '$1' (--help)" ;;
  esac
done
case "$arch" in
  amd64) grub_target=x86_64-efi efi_name=BOOTX64.EFI root_type=4F68BCE3-E8CD-4DB1-96E7-FBCAF984B709
         kernel=linux-image-amd64 qemu_user="" ;;
  arm64) grub_target=arm64-efi efi_name=BOOTAA64.EFI root_type=B921B045-1DF0-41C3-AF44-4C6F280D3FAE
         kernel=linux-image-arm64 qemu_user=aarch64 ;;
  *) die "--arch must be amd64 or arm64, not '$arch'" ;;
esac
[ -n "$out" ] || die "--out DIR is required"
[ -r "$config" ] || die "the robot configuration $config cannot be read"
if [ -z "$orthoflow" ]; then
  orthoflow="$here/build/release/apps/orthoflow"
  [ -x "$orthoflow" ] || orthoflow=$(command -v orthoflow || true)
fi
[ -n "$orthoflow" ] && [ -x "$orthoflow" ] || die "no orthoflow binary for this machine (--orthoflow BIN)"
# The configuration first: a bad one is refused, naming the key, before anything else is needed.
"$orthoflow" image check "$config" || die "$config: not a valid robot configuration (above)"
[ "$(id -u)" = 0 ] || die "needs root (mmdebstrap's root mode keeps the image's owners right)"
if [ -z "$deb" ]; then
  build=release; [ "$arch" = arm64 ] && build=aarch64
  deb=$(ls "$here"/build/$build/deb/orthoflow_*_"$arch".deb 2>/dev/null | head -n 1 || true)
  [ -n "$deb" ] || die "no orthoflow_*_$arch.deb in build/$build/deb (cpack -G DEB -B build/$build/deb --config build/$build/CPackConfig.cmake)"
fi
[ "$(dpkg-deb -f "$deb" Architecture)" = "$arch" ] || die "$deb is not an $arch package"
for tool in mmdebstrap mkfs.ext4 mkfs.vfat mcopy mmd sfdisk grub-mkstandalone zstd systemctl dpkg-query; do
  command -v "$tool" >/dev/null || die "$tool is missing (scripts/install_deps.sh)"
done
[ -d "/usr/lib/grub/$grub_target" ] || die "/usr/lib/grub/$grub_target is missing (grub-efi-$arch-bin)"

# A foreign architecture's maintainer scripts run under qemu-user through binfmt_misc.
if [ -n "$qemu_user" ] && [ "$(dpkg --print-architecture)" != "$arch" ]; then
  if [ ! -e /proc/sys/fs/binfmt_misc/register ]; then
    mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc 2>/dev/null ||
      die "binfmt_misc is not mounted and cannot be (an $arch image needs qemu-user-static through it)"
  fi
  if ! grep -qs '^enabled' "/proc/sys/fs/binfmt_misc/qemu-$qemu_user"; then
    [ -x "/usr/bin/qemu-$qemu_user-static" ] || die "qemu-user-static is missing"
    # Debian's rule, with the static interpreter opened now (F): it works inside the chroot.
    sed "s#:[^:]*:[A-Z]*\$#:/usr/bin/qemu-$qemu_user-static:F#" "/usr/lib/binfmt.d/qemu-$qemu_user.conf" \
      > /proc/sys/fs/binfmt_misc/register || die "cannot register qemu-$qemu_user-static with binfmt_misc"
  fi
fi

started=$(date +%s)
# stamp: each line of its input with the seconds since the build started (the log's time line).
stamp() { while IFS= read -r line; do printf '%4d %s\n' $(( $(date +%s) - started )) "$line"; done; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/orthoflow-image.XXXXXX")
trap 'rm -rf "$work"' EXIT

# 1. The configuration's files (checked above; the graph file it names is checked here).
"$orthoflow" image render "$config" --arch "$arch" --out "$work/render" >/dev/null
if [ -f "$work/render/rootfs/etc/orthoflow/graph.yaml" ]; then
  "$orthoflow" graph check "$work/render/rootfs/etc/orthoflow/graph.yaml" ||
    die "$config: graph: the graph file does not check (above)"
fi
layout() { sed -n "s/^$1 //p" "$work/render/layout"; }
esp_mib=$(layout esp_mib) root_mib=$(layout root_mib) data_mib=$(layout data_mib)
extra=$(layout packages) initramfs=$(layout initramfs)
# The labels fstab and the boot loader find the partitions by: named once, in deploy/image_files.hpp.
root_label=$(layout root_label) data_label=$(layout data_label) esp_label=$(layout esp_label)
initramfs_hooks=()
if [ "$initramfs" = list ]; then
  # Before the kernel is installed, so that its initramfs is made once, with the list.
  initramfs_hooks=(--essential-hook='mkdir -p "$1/etc/initramfs-tools"'
                   --essential-hook="sync-in $here/deploy/image/initramfs /etc/initramfs-tools")
fi

# 2. The root file system: Debian 12 minbase, a kernel, systemd, the orthoflow package.
packages="systemd-sysv,udev,dbus,$kernel,initramfs-tools,kmod,e2fsprogs,dosfstools,iproute2,procps,curl"
packages="$packages,ca-certificates,less,iputils-ping"
[ -n "$extra" ] && packages="$packages,${extra// /,}"
cp "$deb" "$work/orthoflow.deb"
SOURCE_DATE_EPOCH=$(git -C "$here" log -1 --format=%ct 2>/dev/null || date +%s)
export SOURCE_DATE_EPOCH
# In the chroot only what needs apt or the image's own tools. systemd-resolved comes with the
# orthoflow package, in one apt run: it points /etc/resolv.conf at a resolver that only runs on the
# booted robot, so nothing can be fetched after it.
mmdebstrap --verbose --mode=root --variant=minbase --arch="$arch" --include="$packages" "${initramfs_hooks[@]}" \
  --aptopt='Acquire::Retries "3"' \
  --dpkgopt='path-exclude=/usr/share/man/*' --dpkgopt='path-exclude=/usr/share/doc/*' \
  --dpkgopt='path-include=/usr/share/doc/*/copyright' --dpkgopt='path-exclude=/usr/share/locale/*' \
  --dpkgopt='path-exclude=/usr/share/info/*' \
  --customize-hook="copy-in $work/orthoflow.deb /tmp" \
  --customize-hook='chroot "$1" apt-get install -y --no-install-recommends /tmp/orthoflow.deb systemd-resolved' \
  --customize-hook='rm -f "$1/tmp/orthoflow.deb"' \
  --customize-hook='chroot "$1" useradd --system --home-dir /var/lib/orthoflow --no-create-home --shell /usr/sbin/nologin --groups plugdev orthoflow' \
  bookworm "$work/rootfs" "$mirror" 2>&1 | stamp >"$out/mmdebstrap-$arch.log" ||
  { tail -n 40 "$out/mmdebstrap-$arch.log" >&2; die "mmdebstrap failed (its log's end above)"; }
# The rest natively on the directory (also for a foreign architecture): the image's fixed files, the
# configuration's files, the udev rules, the units enabled.
rootfs="$work/rootfs"
cp -a "$here/deploy/image/rootfs/." "$rootfs/"
cp -a "$work/render/rootfs/." "$rootfs/"
cp "$here/deploy/60-orthoflow-kinect.rules" "$here/deploy/60-orthoflow-jaco.rules" "$rootfs/etc/udev/rules.d/"
gid=$(awk -F: '$1 == "orthoflow" {print $3}' "$rootfs/etc/group")
[ -n "$gid" ] || die "the service user was not made"
[ -f "$rootfs/etc/orthoflow/ui-token" ] && chown "0:$gid" "$rootfs/etc/orthoflow/ui-token"
mkdir -p "$rootfs/var/lib/orthoflow" "$rootfs/data" "$rootfs/boot/efi" "$rootfs/usr/share/orthoflow-image"
# openssh-server made host keys while it was installed: every robot flashed from this image would
# share them. The first boot makes the robot's own on the data partition instead.
rm -f "$rootfs"/etc/ssh/ssh_host_*
# What systemd would make in /var/lib at boot, made now: the root is read-only there.
mkdir -p "$rootfs/var/lib/systemd/linger" "$rootfs/var/lib/dbus"
ln -sfn /etc/machine-id "$rootfs/var/lib/dbus/machine-id"
systemctl --root="$rootfs" --quiet enable systemd-networkd.service systemd-resolved.service \
  orthoflow-firstboot.service orthoflow.service orthoflow-health.timer
ln -sfn ../run/systemd/resolve/stub-resolv.conf "$rootfs/etc/resolv.conf"
: > "$rootfs/etc/machine-id"  # empty: systemd makes one per boot on the read-only root
dpkg-query --admindir="$rootfs/var/lib/dpkg" -W -f '${Package} ${Version} ${Architecture}\n' \
  > "$rootfs/usr/share/orthoflow-image/packages.txt"
rootfs_done=$(date +%s)
cp "$rootfs/usr/share/orthoflow-image/packages.txt" "$out/packages-$arch.txt"
if [ -n "$lock" ]; then
  diff -u "$lock" "$out/packages-$arch.txt" >&2 ||
    die "the image's packages differ from $lock (above: - locked, + built)"
fi
cp "$rootfs/boot/$(cd "$rootfs/boot" && ls vmlinuz-* | head -n 1)" "$out/vmlinuz-$arch"
cp "$rootfs/boot/$(cd "$rootfs/boot" && ls initrd.img-* | head -n 1)" "$out/initrd-$arch.img"
cp "$work/render/cmdline" "$out/cmdline-$arch"

# 3. The root file system as a tarball, for boards that bring their own boot loader.
tar -C "$work/rootfs" --numeric-owner --xattrs -cf - . | zstd -q -T0 -9 -o "$out/orthoflow-rootfs-$arch.tar.zst" -f

# 4. The partitions, made as files (no loop device): EFI boot loader, root, data.
grub-mkstandalone -O "$grub_target" -o "$work/$efi_name" \
  --modules="part_gpt part_msdos ext2 fat search search_label linux normal echo test" \
  --locales= --themes= --fonts= "boot/grub/grub.cfg=$work/render/grub.cfg"
mkfs.vfat -n "$esp_label" -C "$work/esp.img" $((esp_mib * 1024)) >/dev/null
mmd -i "$work/esp.img" ::/EFI ::/EFI/BOOT
mcopy -i "$work/esp.img" "$work/$efi_name" "::/EFI/BOOT/$efi_name"
mkfs.ext4 -q -L "$root_label" -d "$work/rootfs" "$work/root.img" "${root_mib}M" ||
  die "the root file system does not fit in image.root_mib $root_mib MiB"
# The data partition: orthoflow/ for the service (bound onto /var/lib/orthoflow), ssh/ for root.
uid=$(awk -F: '$1 == "orthoflow" {print $3 ":" $4}' "$rootfs/etc/passwd")
mkdir -p "$work/data/orthoflow" "$work/data/ssh"
chown "$uid" "$work/data/orthoflow" && chmod 0750 "$work/data/orthoflow" && chmod 0700 "$work/data/ssh"
mkfs.ext4 -q -L "$data_label" -m 0 -d "$work/data" "$work/data.img" "${data_mib}M"

# 5. The disk: GPT with the three partitions, 1 MiB aligned.
img="$out/orthoflow-$arch.img"
rm -f "$img"
truncate -s $(( (2 + esp_mib + root_mib + data_mib) * 1024 * 1024 )) "$img"
sfdisk --quiet "$img" <<EOF
label: gpt
start=2048, size=$((esp_mib * 2048)), type=C12A7328-F81F-11D2-BA4B-00A0C93EC93B, name="EFI"
size=$((root_mib * 2048)), type=$root_type, name="$root_label"
size=$((data_mib * 2048)), type=0FC63DAF-8483-4772-8E79-3D69D8477DE4, name="$data_label"
EOF
offset=1
for part in esp:$esp_mib root:$root_mib data:$data_mib; do
  dd if="$work/${part%%:*}.img" of="$img" bs=1M seek=$offset conv=notrunc,sparse status=none
  offset=$((offset + ${part##*:}))
done
finished=$(date +%s)

used_kib=$(du -sk "$work/rootfs" | cut -f1)
{
  echo "orthoflow image $arch built $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "package: $(basename "$deb") ($(dpkg-deb -f "$deb" Version))"
  echo "config: $config"
  echo "mirror: $mirror (Debian 12 bookworm), $(wc -l < "$out/packages-$arch.txt") packages (packages-$arch.txt)"
  echo "root file system: $((used_kib / 1024)) MiB used of $root_mib MiB; esp $esp_mib MiB; data $data_mib MiB"
  echo "disk image: $(du -h --apparent-size "$img" | cut -f1) ($(du -h "$img" | cut -f1) allocated)"
  echo "rootfs tarball: $(du -h "$out/orthoflow-rootfs-$arch.tar.zst" | cut -f1)"
  echo "time: root file system $((rootfs_done - started)) s, image $((finished - rootfs_done)) s"
} | tee "$out/build-$arch.txt"
