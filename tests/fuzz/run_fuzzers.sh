#!/usr/bin/env bash
# usage: run_fuzzers.sh SECONDS FUZZER...
# Runs each libFuzzer binary for SECONDS on a fresh corpus seeded with the committed seeds and the
# shared data files; exits non-zero on any crash, leak, timeout or sanitizer report.
set -euo pipefail
seconds=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
shared="${ORTHOFLOW_SHARED_DIR:-$here/../../../shared}"
status=0
for fuzzer in "$@"; do
  name=$(basename "$fuzzer")
  kind=${name#fuzz_}
  kind=${kind%_reader}
  corpus=$(mktemp -d)
  cp "$here/corpus/$kind/"* "$corpus/" 2>/dev/null || true
  if [ "$kind" = pcd ] && [ -d "$shared" ]; then
    # Small shared files only: big organized frames make each execution slow.
    find "$shared" -name '*.pcd' -size -200k -exec cp {} "$corpus/" \; 2>/dev/null || true
  fi
  artifacts=$(mktemp -d)
  echo "fuzz: $name for ${seconds}s, $(ls "$corpus" | wc -l) seeds"
  if ! "$fuzzer" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" 2>"$artifacts/log"; then
    tail -40 "$artifacts/log"
    echo "fuzz: $name FAILED (artifacts in $artifacts)"
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$artifacts/log" || true
    tail -1 "$artifacts/log"
  fi
  rm -rf "$corpus"
done
exit $status
