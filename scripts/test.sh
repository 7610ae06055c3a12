#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run calls exactly this):
#   1. release preset: unit, integration and PCL cross-check tests (ctest);
#   2. asan preset: the same suite under AddressSanitizer + UndefinedBehaviorSanitizer;
#   3. fuzz preset: every libFuzzer target for FUZZ_SECONDS (default 60) seconds each, FUZZ_JOBS
#      (default 2) at a time;
#   4. aarch64 preset (without its benchmarks): cross-built with toolchains/aarch64-linux-gnu.cmake,
#      ctest under qemu, then
#      `cpack` of the release and aarch64 builds (one check each: orthoflow_<ver>_<arch>.deb).
#      AARCH64=0 skips the stage.
#   5. image (after the aarch64 stage, from its two packages): an amd64 and an arm64 robot image built
#      by scripts/build_image.sh from tests/image/robot.yaml and booted under qemu-system by
#      scripts/test_image.sh (issue 24). IMAGE=0 skips the stage; IMAGE_ARCHES picks (default both).
# Prints the skipped tests with their reasons per stage, a table of passed / failed / skipped per
# stage, and a closing line "tests: N passed, M failed, K skipped"; exits non-zero on any failure.
# With CI=true (.ci/run sets it), a skipped or missing must-run test is a failure naming its
# prerequisite (scripts/ctest_gate.py, tests/must_run.txt); outside CI it is listed as a skip.
set -uo pipefail
cd "$(dirname "$0")/.."
FUZZ_SECONDS="${FUZZ_SECONDS:-60}"
PRESETS="${PRESETS:-release asan}"
passed=0
failed=0
skipped=0
stages=""    # one "stage | passed | failed | skipped" row per stage
ci_flag=""
[ "${CI:-}" = true ] && ci_flag="--ci"
failures=""  # "preset/test" names, printed again at the very end where a truncated log still shows them
timings=""   # one "stage: seconds" line per stage
logdir=$(mktemp -d)
start=$(date +%s)

# note_time STAGE SINCE: records how long STAGE took since the epoch second SINCE.
note_time() { timings="$timings$1: $(( $(date +%s) - $2 )) s"$'\n'; }

# Compiler cache: four presets compile the product four times, and CI runs on the machine of the
# session that submitted, right after it. With ccache (installed by install_deps.sh) a file unchanged
# since the last build of the same preset is not compiled again, whichever clone built it
# (CCACHE_BASEDIR makes the paths relative; CCACHE_NOHASHDIR leaves the build folder out of the hash
# of -g objects). A cold cache changes nothing but the time. ORTHOFLOW_NO_CCACHE=1 turns it off.
if [ "${ORTHOFLOW_NO_CCACHE:-0}" != 1 ] && command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1 CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-8G}"
fi

# run_ctest_preset NAME [CMAKE_ARGS...]: configure (with CMAKE_ARGS), build and test one preset;
# adds its counts to the totals.
run_ctest_preset() {
  local preset=$1 log="$logdir/$1.log" t0
  shift
  t0=$(date +%s)
  echo "=== preset $preset: configure and build"
  if ! { cmake --preset "$preset" "$@" >"$logdir/$preset.configure.log" && cmake --build --preset "$preset"; }; then
    cat "$logdir/$preset.configure.log"
    echo "preset $preset: build FAILED"
    failed=$((failed + 1))
    failures="$failures$preset: build"$'\n'
    return
  fi
  note_time "$preset build" "$t0"
  t0=$(date +%s)
  echo "=== preset $preset: ctest"
  ctest --preset "$preset" --output-junit "$logdir/$preset.junit.xml" 2>&1 | tee "$log"
  note_time "$preset ctest" "$t0"
  # The failed tests' names from ctest's own list ("  12 - name (Failed)"), and the end of each one's
  # output from ctest's LastTest.log, printed again at the very end (a truncated CI log keeps its tail).
  local names n
  names=$(sed -n '/The following tests FAILED:/,$p' "$log" | sed -n -E 's/^[[:space:]]+[0-9]+ - (.*)$/\1/p')
  while IFS= read -r n; do
    [ -n "$n" ] || continue
    failures="$failures$preset: $n"$'\n'
    echo "## $preset: $n" >>"$logdir/failure_tails.txt"
    awk -v t=" Testing: ${n%% (*}" 'substr($0, length($0) - length(t) + 1) == t {on = 1; next}
      on && /^<end of output>/ {exit} on' "build/$preset/Testing/Temporary/LastTest.log" 2>/dev/null |
      tail -n 25 >>"$logdir/failure_tails.txt"
  done <<<"$names"
  if ! grep -qE "tests passed, [0-9]+ tests failed out of [0-9]+" "$log"; then
    echo "preset $preset: ctest gave no summary"
    failed=$((failed + 1))
    failures="$failures$preset: ctest gave no summary"$'\n'
    return
  fi
  gate_stage "$preset" "build/$preset" "$logdir/$preset.junit.xml"
}

# gate_stage STAGE BUILD_DIR JUNIT: counts passed / failed / skipped with scripts/ctest_gate.py (a
# must-run test skipped or missing fails in CI), lists every skip with its reason, and adds the stage
# to the totals and the per-stage table.
gate_stage() {
  local stage=$1 out problems p f k line
  out=$(python3 scripts/ctest_gate.py --stage "$stage" --build "$2" --junit "$3" \
        --manifest tests/must_run.txt $ci_flag)
  echo "$out" | sed -n 's/^GATE FAILURE //p; /^GATE /!p'
  problems=$(echo "$out" | sed -n 's/^GATE FAILURE //p')
  [ -n "$problems" ] && failures="$failures$problems"$'\n'
  line=$(echo "$out" | grep -E "^GATE $stage passed=" | tail -1)
  p=$(echo "$line" | sed -E 's/.*passed=([0-9]+).*/\1/')
  f=$(echo "$line" | sed -E 's/.*failed=([0-9]+).*/\1/')
  k=$(echo "$line" | sed -E 's/.*skipped=([0-9]+).*/\1/')
  [ -n "$line" ] || { p=0; f=1; k=0; failures="$failures$stage: no test gate result"$'\n'; }
  passed=$((passed + p))
  failed=$((failed + f))
  skipped=$((skipped + k))
  stages="$stages$(printf '%-10s %8s %8s %8s' "$stage" "$p" "$f" "$k")"$'\n'
}

# collect_fuzzer PID NAME: waits for one background fuzzer, prints its log and counts its result.
collect_fuzzer() {
  local pid=$1 name=$2
  if wait "$pid"; then
    cat "$logdir/$name.fuzz.log"
    passed=$((passed + 1))
  else
    cat "$logdir/$name.fuzz.log"
    echo "fuzzer $name FAILED"
    failed=$((failed + 1))
    failures="${failures}fuzz: $name"$'\n'
  fi
}

run_fuzzers() {
  local t0
  t0=$(date +%s)
  echo "=== preset fuzz: configure and build"
  if ! { cmake --preset fuzz >"$logdir/fuzz.configure.log" && cmake --build --preset fuzz; }; then
    cat "$logdir/fuzz.configure.log"
    echo "preset fuzz: build FAILED"
    failed=$((failed + 1))
    return
  fi
  note_time "fuzz build" "$t0"
  # Two fuzzers at a time: each libFuzzer process is single-threaded and CI has two cores. Each
  # one's output goes to its own log, printed whole when it ends (never interleaved).
  local f pids=() names=() i
  t0=$(date +%s)
  for f in build/fuzz/tests/fuzz/fuzz_*; do
    [ -x "$f" ] || continue
    echo "=== fuzzing $(basename "$f") for ${FUZZ_SECONDS}s"
    bash tests/fuzz/run_fuzzers.sh "$FUZZ_SECONDS" "$f" >"$logdir/$(basename "$f").fuzz.log" 2>&1 &
    pids+=($!)
    names+=("$(basename "$f")")
    if [ ${#pids[@]} -ge "${FUZZ_JOBS:-2}" ]; then
      collect_fuzzer "${pids[0]}" "${names[0]}"
      pids=("${pids[@]:1}")
      names=("${names[@]:1}")
    fi
  done
  for i in "${!pids[@]}"; do collect_fuzzer "${pids[$i]}" "${names[$i]}"; done
  note_time "fuzz" "$t0"
}

# undeclared_libraries DEB ARCH: each shared library /usr/bin/orthoflow in DEB needs (readelf NEEDED) whose
# ARCH package (dpkg -S) the deb's Depends does not name; nothing when all are named. The arm64 Depends
# is a written list (cross builds run no dpkg-shlibdeps): a new library must not reach the image unnamed.
undeclared_libraries() {
  local deb=$1 arch=$2 tmp depends soname owner missing="" triplet=x86_64-linux-gnu
  [ "$arch" = arm64 ] && triplet=aarch64-linux-gnu
  tmp=$(mktemp -d)
  dpkg-deb -x "$deb" "$tmp"
  depends=" $(dpkg-deb -f "$deb" Depends | tr ',|' '  ') "
  for soname in $(readelf -d "$tmp/usr/bin/orthoflow" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    owner=$(dpkg -S "*/$triplet/$soname" 2>/dev/null | head -n 1 | sed 's/[:,].*//')
    [ -z "$owner" ] && { missing="$missing $soname(no $arch package)"; continue; }
    case "$depends" in *" $owner "*) ;; *) missing="$missing $soname($owner)" ;; esac
  done
  rm -rf "$tmp"
  echo "${missing# }"
}

# check_deb BUILD_DIR ARCH: cpack -G DEB into BUILD_DIR/deb, then the file name, its Architecture field and
# a Depends that names every library the binary needs.
check_deb() {
  local dir=$1 arch=$2 deb
  rm -rf "$dir/deb"
  if ! cpack -G DEB -B "$dir/deb" --config "$dir/CPackConfig.cmake" >"$logdir/cpack_$arch.log" 2>&1; then
    cat "$logdir/cpack_$arch.log"
    echo "package $arch: cpack FAILED"
    failed=$((failed + 1))
    failures="${failures}package $arch: cpack"$'\n'
    return
  fi
  deb=$(ls "$dir"/deb/orthoflow_*_"$arch".deb 2>/dev/null | head -1)
  [ -n "$deb" ] && dpkg-deb -c "$deb" >"$logdir/contents_$arch.txt"
  local missing=""
  [ -n "$deb" ] && missing=$(undeclared_libraries "$deb" "$arch")
  if [ -n "$missing" ]; then
    echo "package $arch: /usr/bin/orthoflow needs libraries its Depends does not name: $missing"
    failed=$((failed + 1))
    failures="${failures}package $arch: Depends"$'\n'
  elif [ -n "$deb" ] && [ "$(dpkg-deb -f "$deb" Architecture)" = "$arch" ] && grep -q "/usr/bin/orthoflow$" "$logdir/contents_$arch.txt"; then
    echo "package $arch: $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB; Depends: $(dpkg-deb -f "$deb" Depends))"
    passed=$((passed + 1))
  else
    echo "package $arch: no orthoflow_*_$arch.deb holding /usr/bin/orthoflow"
    failed=$((failed + 1))
    failures="${failures}package $arch: contents"$'\n'
  fi
}

# The aarch64 stage (issue 10): cross build, every test under qemu-aarch64-static, arm64 and amd64 packages.
# Its benchmarks are not built here: none runs under qemu, the release stage compiles the same
# sources, and the preset still builds them for a user's board.
run_aarch64() {
  run_ctest_preset aarch64 -DBUILD_BENCHMARKS=OFF
  [ -f build/aarch64/CPackConfig.cmake ] && check_deb build/aarch64 arm64
  [ -f build/release/CPackConfig.cmake ] && check_deb build/release amd64
}

# The image stage (issue 24): build each architecture's robot image from the packages check_deb made,
# boot it under qemu-system and check it from the host (scripts/test_image.sh). One check per image.
run_image() {
  local t0 arch out=build/image
  t0=$(date +%s)
  mkdir -p "$out"
  # The packages come from the aarch64 stage; made here when that stage did not run.
  ls build/release/deb/orthoflow_*_amd64.deb >/dev/null 2>&1 || check_deb build/release amd64
  # The test configuration with an admin key made now (never committed): boot 2 logs in with it and
  # updates the package in place.
  local cfg="$out/config" deb
  rm -rf "$cfg" && mkdir -p "$cfg" && cp tests/image/robot.yaml tests/image/ui-token "$cfg/"
  ssh-keygen -q -t ed25519 -N '' -C orthoflow-image-test -f "$cfg/admin_key"
  printf 'admin:\n  ssh_authorized_keys: admin_key.pub\n' >> "$cfg/robot.yaml"
  for arch in ${IMAGE_ARCHES:-amd64 arm64}; do
    echo "=== image $arch: build"
    if ! bash scripts/build_image.sh --arch "$arch" --out "$out" --config "$cfg/robot.yaml" \
        >"$logdir/image_build_$arch.log" 2>&1; then
      tail -n 40 "$logdir/image_build_$arch.log"
      echo "image $arch: build FAILED"
      failed=$((failed + 1)); failures="${failures}image $arch: build"$'\n'
      continue
    fi
    tail -n 7 "$logdir/image_build_$arch.log"
    echo "=== image $arch: boot"
    deb=$(ls build/release/deb/orthoflow_*_"$arch".deb build/aarch64/deb/orthoflow_*_"$arch".deb 2>/dev/null | head -n 1)
    if bash scripts/test_image.sh --arch "$arch" --dir "$out" --token "$cfg/ui-token" --ssh-key "$cfg/admin_key" --deb "$deb" \
        >"$logdir/image_boot_$arch.log" 2>&1; then
      cat "$out/boot-$arch.txt"
      passed=$((passed + 1))
    else
      tail -n 80 "$logdir/image_boot_$arch.log"
      echo "image $arch: boot test FAILED"
      failed=$((failed + 1)); failures="${failures}image $arch: boot"$'\n'
    fi
    rm -f "$out/orthoflow-$arch.img"  # 2 GiB each; the tarball, lists and logs stay
  done
  note_time "image" "$t0"
}

for p in $PRESETS; do run_ctest_preset "$p"; done
if [ "$FUZZ_SECONDS" -gt 0 ]; then run_fuzzers; fi
if [ "${AARCH64:-1}" != 0 ]; then run_aarch64; fi
if [ "${IMAGE:-1}" != 0 ]; then run_image; fi
echo "--- time per stage"
printf "%s" "$timings"
echo "--- tests per stage (ctest stages; fuzz, packages and images count as passed or failed)"
printf '%-10s %8s %8s %8s\n' stage passed failed skipped
printf "%s" "$stages"
[ -n "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ] && ccache -s 2>/dev/null | grep -E "^(Cacheable calls|  Hits|  Misses)" || true
if [ -n "$failures" ]; then
  echo "--- the end of each failed test's output"
  cat "$logdir/failure_tails.txt" 2>/dev/null
  echo "--- FAILED"
  printf "%s" "$failures"
fi
rm -rf "$logdir"
echo "elapsed: $(( $(date +%s) - start )) s"
echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
