#!/usr/bin/env bash
# usage: run_fuzzers.sh SECONDS [FUZZ_BUILD_DIR | FUZZER_BINARY]...
# Runs libFuzzer binaries that are already built (default: every fuzz_*_reader and fuzz_jaco_reply
# under build/fuzz, the `fuzz` preset; a directory argument means every fuzzer under it, a file
# argument that one fuzzer) for SECONDS each, on a fresh temporary corpus seeded with the committed
# seeds and the small PCD files of the shared data. Builds nothing. Exits non-zero on any crash, leak,
# timeout, OOM or sanitizer report. FUZZERS="pcd" (or "ply", "jaco_reply") restricts directory
# arguments to some kinds; KEEP_CORPUS=DIR keeps the grown corpora in DIR/<kind>.
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 SECONDS [FUZZ_BUILD_DIR | FUZZER_BINARY]..." >&2
  exit 2
fi
seconds=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
[ $# -gt 0 ] || set -- "$here/../../build/fuzz"
shared="${ORTHOFLOW_SHARED_DIR:-$here/../../../shared}"  # the shared data beside the checkout
fuzzers=()
for arg in "$@"; do
  if [ -d "$arg" ]; then
    for kind in ${FUZZERS:-pcd ply jaco_reply}; do
      found=$(find "$arg" -type f -perm -u+x \( -name "fuzz_${kind}_reader" -o -name "fuzz_${kind}" \) | head -1)
      if [ -z "$found" ]; then
        echo "fuzz: fuzz_${kind}[_reader] not found under $arg (build the fuzz preset first)" >&2
        exit 1
      fi
      fuzzers+=("$found")
    done
  elif [ -x "$arg" ]; then
    fuzzers+=("$arg")
  else
    echo "fuzz: $arg is neither a build directory nor a fuzzer binary" >&2
    exit 1
  fi
done
status=0
for fuzzer in "${fuzzers[@]}"; do
  kind=$(basename "$fuzzer")
  kind=${kind#fuzz_}
  kind=${kind%_reader}
  corpus=$(mktemp -d)
  cp "$here/corpus/$kind/"* "$corpus/" 2>/dev/null || true  # a new kind may have no seeds yet
  if [ "$kind" = pcd ] && [ -d "$shared" ]; then
    # Small shared files only: big organized frames make each execution slow.
    find "$shared" -name '*.pcd' -size -40k -exec cp {} "$corpus/" \; 2>/dev/null || true
  fi
  artifacts=$(mktemp -d)
  echo "fuzz: $(basename "$fuzzer") for ${seconds}s, $(ls "$corpus" | wc -l) seeds"
  if ! "$fuzzer" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" 2>"$artifacts/log"; then
    tail -40 "$artifacts/log"
    echo "fuzz: $(basename "$fuzzer") FAILED (log and crashing input in $artifacts)"
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$artifacts/log" || true
    grep -E "^#[0-9]+.*(cov|DONE)" "$artifacts/log" | tail -1 || true
    echo "fuzz: corpus grew to $(ls "$corpus" | wc -l) inputs"
    rm -rf "$artifacts"
  fi
  if [ -n "${KEEP_CORPUS:-}" ]; then
    mkdir -p "$KEEP_CORPUS/$kind" && cp "$corpus/"* "$KEEP_CORPUS/$kind/"
  fi
  rm -rf "$corpus"
done
exit $status
