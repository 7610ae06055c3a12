#!/bin/sh
# Kinect depth under packet loss: libfreenect 0.5.3 vs orthoflow's KinectCamera on the same simulated
# stream (issue 18). Builds nothing; runs, for each loss rate, both host drivers against the sim_libusb
# shim (LD_LIBRARY_PATH) with the same ORTHOFLOW_SIM_KINECT (same scene, same fault seed), compares
# every delivered frame with SimKinectDevice::depth_raw_image (loss_vs_libfreenect.cpp) and prints one
# table (Markdown).
#
# usage: bench/drivers/kinect/loss_vs_libfreenect.sh [FRAMES [DROP ...]]     (default: 300 0.01)
#   FRAMES  stream frames counted, k = 0 .. FRAMES-1 (the simulator's frame index since stream start)
#   DROP    per-packet drop rate of the simulated bus (one table column pair per rate)
# environment (all optional):
#   BUILD            build tree (default build/release, relative to the repository root)
#   LOSS_BENCH       the loss_vs_libfreenect binary      (default $BUILD/bench/drivers/loss_vs_libfreenect)
#   FREENECT_CLIENT  tests/support/sim_libusb's client   (default $BUILD/tests/support/sim_libusb/sim_libusb_freenect_client)
#   SIM_LIBUSB_DIR   the shim's directory                (default $BUILD/tests/support/sim_libusb/lib)
#   LOSS_KINECT      the Kinect without its drop rate    (default model=1414,depth=ramp,fault_seed=7)
#   ORTHOFLOW_SIM_KINECT_PACE  realtime (default: 30 frames per wall-clock second) or max
# Build first: cmake --build build/release --target loss_vs_libfreenect sim_libusb_freenect_client orthoflow_sim_libusb
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${BUILD:-build/release}
case $BUILD in /*) ;; *) BUILD=$root/$BUILD ;; esac
LOSS_BENCH=${LOSS_BENCH:-$BUILD/bench/drivers/loss_vs_libfreenect}
FREENECT_CLIENT=${FREENECT_CLIENT:-$BUILD/tests/support/sim_libusb/sim_libusb_freenect_client}
SIM_LIBUSB_DIR=${SIM_LIBUSB_DIR:-$BUILD/tests/support/sim_libusb/lib}
LOSS_KINECT=${LOSS_KINECT:-model=1414,depth=ramp,fault_seed=7}
PACE=${ORTHOFLOW_SIM_KINECT_PACE:-realtime}
frames=${1:-300}
[ $# -gt 0 ] && shift
[ $# -eq 0 ] && set -- 0.01

for f in "$LOSS_BENCH" "$FREENECT_CLIENT" "$SIM_LIBUSB_DIR/libusb-1.0.so.0"; do
  [ -e "$f" ] || { echo "loss_vs_libfreenect.sh: $f is missing (build it first)" >&2; exit 2; }
done
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

status=0
runs=""
i=0
for drop in "$@"; do
  i=$((i + 1))
  kinect="$LOSS_KINECT,drop=$drop"
  # libfreenect: the C client streams its callbacks' frames; the comparison reads them from the pipe.
  { LD_LIBRARY_PATH=$SIM_LIBUSB_DIR ORTHOFLOW_SIM_KINECT=$kinect ORTHOFLOW_SIM_KINECT_PACE=$PACE \
      "$FREENECT_CLIENT" 11bit "$frames" - 2>"$tmp/fn$i.err"; echo $? >"$tmp/fn$i.rc"; } |
    ORTHOFLOW_SIM_KINECT=$kinect "$LOSS_BENCH" freenect "$frames" >"$tmp/fn$i.kv" 2>>"$tmp/fn$i.err"
  rc=$?
  if [ "$rc" -ne 0 ] || [ "$(cat "$tmp/fn$i.rc")" -ne 0 ]; then
    echo "loss_vs_libfreenect.sh: libfreenect run failed (drop=$drop):" >&2
    tail -n 20 "$tmp/fn$i.err" >&2
    status=1
  fi
  # orthoflow: KinectCamera on LibusbTransport, default CameraOptions, through the same shim.
  LD_LIBRARY_PATH=$SIM_LIBUSB_DIR ORTHOFLOW_SIM_KINECT=$kinect ORTHOFLOW_SIM_KINECT_PACE=$PACE \
    "$LOSS_BENCH" orthoflow "$frames" >"$tmp/of$i.kv" 2>"$tmp/of$i.err"
  if [ $? -ne 0 ]; then
    echo "loss_vs_libfreenect.sh: orthoflow run failed (drop=$drop):" >&2
    tail -n 20 "$tmp/of$i.err" >&2
    status=1
  fi
  runs="$runs $drop:$tmp/fn$i.kv:$tmp/of$i.kv"
done

echo "Simulated Kinect ($LOSS_KINECT, drop=<rate>), pace $PACE, frames k = 0..$((frames - 1))"
echo "(simulator stream, the documented protocol; not compared with hardware)"
echo
awk -v runs="$runs" '
function val(file, key,    line, parts, v) {
  v = "-"
  while ((getline line < file) > 0) { split(line, parts, " "); if (parts[1] == key) v = parts[2] }
  close(file)
  return v
}
function row(label, kf, ko,    n, r, parts, s) {
  s = sprintf("| %-46s", label)
  for (r = 1; r <= nruns; r++) {
    split(run[r], parts, ":")
    s = s sprintf(" | %11s | %11s", kf == "" ? "-" : val(parts[2], kf), ko == "" ? "-" : val(parts[3], ko))
  }
  print s " |"
}
BEGIN {
  nruns = split(substr(runs, 2), run, " ")
  s = sprintf("| %-46s", "per-packet drop rate"); d = "|" sprintf("%48s", "") 
  gsub(/ /, "-", d)
  for (r = 1; r <= nruns; r++) {
    split(run[r], parts, ":")
    s = s sprintf(" | %11s | %11s", "lf " parts[1], "of " parts[1])
    d = d "|-------------|-------------"
  }
  print s " |"; print d "|"
  row("frames the device sent", "periods", "periods")
  row("delivered to the application", "delivered", "delivered")
  row("  bit-identical to the simulator frame", "identical", "identical")
  row("  degraded: holes (2047) only, rest exact", "holes_only", "holes_only")
  row("  with wrong pixels (not 2047, not the truth)", "wrong_frames", "wrong_frames")
  row("wrong pixels", "wrong_pixels", "wrong_pixels")
  row("  = previous frame value (stale)", "wrong_stale", "wrong_stale")
  row("  = next frame value", "wrong_next", "wrong_next")
  row("  other (garbage)", "wrong_garbage", "wrong_garbage")
  row("max wrong pixels in one frame", "max_wrong_per_frame", "max_wrong_per_frame")
  row("hole pixels (2047 where the truth is not)", "hole_pixels", "hole_pixels")
  row("dropped by the driver (too many holes)", "", "health_frames_dropped")
  row("never delivered", "never_delivered", "never_delivered")
  row("content of another frame than its timestamp", "misnumbered", "misnumbered")
  row("delivered twice", "duplicates", "duplicates")
  row("driver: packets counted lost", "", "health_lost_packets")
  row("driver: resyncs", "", "health_resyncs")
  row("driver: frames abandoned to a resync", "", "health_frames_abandoned")
  row("driver: frames overwritten before read", "", "health_frames_overwritten")
}'
exit $status
