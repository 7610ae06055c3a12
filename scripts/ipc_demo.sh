#!/usr/bin/env bash
# The two-process example (docs/IPC.md): graphs/sensor.yaml publishes the synthetic session's frames
# over iceoryx, graphs/perception.yaml runs the tabletop graph on them in another process.
# Starts RouDi (with pools sized by `orthoflow ipc config`) if none is running, and stops it again.
# Usage: bash scripts/ipc_demo.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="${1:-build/release}/apps/orthoflow"
[ -x "$BIN" ] || { echo "ipc_demo: build first: cmake --build --preset release --target orthoflow_cli"; exit 2; }
work=$(mktemp -d)
roudi_pid=""
cleanup() {
  [ -n "$roudi_pid" ] && kill -TERM "$roudi_pid" 2>/dev/null && wait "$roudi_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
if ! "$BIN" ipc doctor >/dev/null 2>&1; then
  "$BIN" ipc config graphs/sensor.yaml graphs/perception.yaml >"$work/roudi.toml"
  echo "ipc_demo: starting RouDi ($work/roudi.toml)"
  setsid iox-roudi -c "$work/roudi.toml" </dev/null >"$work/roudi.log" 2>&1 &
  roudi_pid=$!
  for _ in $(seq 50); do "$BIN" ipc doctor >/dev/null 2>&1 && break; sleep 0.2; done
  "$BIN" ipc doctor >/dev/null || { cat "$work/roudi.log"; echo "ipc_demo: RouDi did not come up"; exit 1; }
fi
"$BIN" graph run graphs/perception.yaml >"$work/perception.txt" 2>&1 &
perception=$!
sleep 1  # let the subscriber register before the first frame
"$BIN" graph run graphs/sensor.yaml
wait "$perception" || { cat "$work/perception.txt"; exit 1; }
echo "--- perception process (frames read in place from the sensor process):"
cat "$work/perception.txt"
