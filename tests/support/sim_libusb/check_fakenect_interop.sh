#!/usr/bin/env bash
# Recordings move both ways between orthoflow and libfreenect (issue 18), checked with libfreenect's
# own tools (Debian's libfreenect 0.5.3, test-only):
#  1. libfreenect's fakenect-record, on the simulated Kinect through the sim_libusb shim, records a
#     directory; `orthoflow run --source replay:DIR` replays every depth record of it.
#  2. `orthoflow kinect record --sim` records a directory; libfreenect's fakenect replay library
#     (the `fakenect` wrapper) plays it to an unmodified libfreenect program (freenect_client),
#     which receives our depth records bit for bit.
# usage: check_fakenect_interop.sh ORTHOFLOW FREENECT_CLIENT SHIM_DIR WORK_DIR
set -euo pipefail
cli=$1 client=$2 shim=$3 work=$4
rm -rf "$work" && mkdir -p "$work"

# 1. libfreenect records, orthoflow replays.
LD_LIBRARY_PATH="$shim" timeout -s INT 2 fakenect-record "$work/lf" >"$work/lf.log" 2>&1 || true
n=$(grep -c '^d-' "$work/lf/INDEX.txt")
[ "$n" -ge 20 ] || { echo "FAIL: fakenect-record wrote $n depth records"; cat "$work/lf.log"; exit 1; }
# Debian's 0.5.3 writes no device.json (added in 0.6.0): the replay uses the typical device.
"$cli" run --source "replay:$work/lf" --rate max --threads 1 >"$work/replay.txt" 2>&1
grep -q "frames: *$n processed" "$work/replay.txt" || { echo "FAIL: replay of fakenect-record"; cat "$work/replay.txt"; exit 1; }
grep -q "$n with a table" "$work/replay.txt" || { echo "FAIL: replay found no table"; cat "$work/replay.txt"; exit 1; }

# 2. orthoflow records, libfreenect replays.
"$cli" kinect record "$work/of" --sim --frames 8 >/dev/null
mkdir -p "$work/out"
FAKENECT_LOOP=0 fakenect "$work/of" "$client" 11bit 8 "$work/out" >"$work/client.log" 2>&1 \
  || { echo "FAIL: freenect_client under fakenect"; cat "$work/client.log"; exit 1; }
i=0
for d in $(grep '^d-' "$work/of/INDEX.txt"); do
  tail -c 614400 "$work/of/$d" | cmp -s - "$work/out/11bit-$i.raw" \
    || { echo "FAIL: libfreenect's frame $i differs from our record $d"; exit 1; }
  i=$((i + 1))
done
[ "$i" -eq 8 ] || { echo "FAIL: compared $i frames"; exit 1; }
echo "ok: fakenect-record -> orthoflow replay: $n frames; orthoflow record -> libfreenect fakenect: $i frames bit for bit"
