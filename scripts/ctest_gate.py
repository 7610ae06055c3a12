#!/usr/bin/env python3
"""The test gate of one ctest stage: counts passed, failed and skipped tests from ctest's JUnit
report, and decides which skips fail the stage (STYLE rule 23).

- A test labelled `must_run` (a release must run it: browser, RouDi sandbox, DDS, network loss,
  libfreenect against the simulated camera, the arm through the libusb shim) that was skipped is a
  failure when CI=true, naming the prerequisite it reported; outside CI it is listed as a skip.
- A test labelled `hardware` (KINECT_HW, JACO_HW) may always skip; it never gates.
- tests/must_run.txt lists the must-run tests each stage must hold. One that is absent from the
  stage (a folder that was not configured, a dependency CMake did not find) is a failure in CI.
Labels are matched as words inside the label text, because gtest_discover_tests joins a test's
labels with '_' (tests/CMakeLists.txt).

Prints one line per skipped test with its reason, one per gate failure, then
`GATE <stage> passed=N failed=M skipped=K` for scripts/test.sh to add up. Exits 0.

usage: ctest_gate.py --stage NAME --build DIR --junit FILE [--manifest FILE] [--ci]
       ctest_gate.py --self-test
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET


def has_label(labels, word):
    """True if @p word is one of the labels or a '_'-separated part of one."""
    return any(word == label or re.search(r"(^|_)%s($|_)" % re.escape(word), label) for label in labels)


def labels_by_test(build):
    """{test name: [labels]} from `ctest --show-only=json-v1`."""
    out = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"], capture_output=True, text=True,
                         check=False).stdout
    try:
        data = json.loads(out)
    except ValueError:
        return {}
    result = {}
    for test in data.get("tests", []):
        labels = []
        for prop in test.get("properties", []):
            if prop.get("name") == "LABELS":
                labels = list(prop.get("value") or [])
        result[test.get("name")] = labels
    return result


def skip_reason(output):
    """The reason a skipped test gave: GoogleTest's text after `Skipped`, or a script's `SKIP: ...`."""
    lines = (output or "").splitlines()
    for i, line in enumerate(lines):
        if line.rstrip().endswith(": Skipped") or line.strip() == "Skipped":
            reason = [l.strip() for l in lines[i + 1:i + 4] if l.strip() and not l.startswith("[")]
            if reason:
                return " ".join(reason)[:300]
        match = re.match(r"^\s*SKIP:\s*(.+)$", line)
        if match:
            return match.group(1).strip()[:300]
    return "no reason given"


def results(junit):
    """[(name, status, text)] with status pass, fail, skip or disabled."""
    tree = ET.parse(junit)
    found = []
    for case in tree.iter("testcase"):
        name = case.get("name")
        status = case.get("status", "run")
        out = case.findtext("system-out") or ""
        if case.find("failure") is not None or status == "fail":
            found.append((name, "fail", out))
        elif status == "disabled":
            found.append((name, "disabled", out))
        elif case.find("skipped") is not None or status == "notrun":
            found.append((name, "skip", out))
        else:
            found.append((name, "pass", out))
    return found


def manifest_entries(path, stage):
    """(regex, prerequisite) of the manifest lines naming @p stage."""
    entries = []
    if not path or not os.path.exists(path):
        return entries
    with open(path, encoding="utf-8") as text:
        for line in text:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            stages, regex, prerequisite = line.split(None, 2)
            if stage in stages.split(","):
                entries.append((regex, prerequisite))
    return entries


def gate(stage, labels, found, manifest, ci, out):
    passed = failed = skipped = 0
    problems = []
    for name, status, text in found:
        test_labels = labels.get(name, [])
        if status == "pass":
            passed += 1
        elif status == "fail":
            failed += 1
        elif status in ("skip", "disabled"):
            skipped += 1
            reason = skip_reason(text) if status == "skip" else "disabled"
            kind = "hardware" if has_label(test_labels, "hardware") else (
                "must-run" if has_label(test_labels, "must_run") else "optional")
            out.write("skipped [%s] %s: %s: %s\n" % (stage, kind, name, reason))
            if kind == "must-run" and ci:
                problems.append("%s: must-run test skipped: %s (prerequisite: %s)" % (stage, name, reason))
    ran = [name for name, status, _ in found if status in ("pass", "fail")]
    present = [name for name, _, _ in found]
    for regex, prerequisite in manifest:
        pattern = re.compile(regex)
        if not any(pattern.search(name) for name in present):
            message = "%s: must-run test missing: %s (needs %s)" % (stage, regex, prerequisite)
            if ci:
                problems.append(message)
            else:
                out.write("warning: " + message + "\n")
        elif ci and not any(pattern.search(name) for name in ran):
            pass  # every match skipped: reported above, test by test
    for problem in problems:
        out.write("GATE FAILURE " + problem + "\n")
    failed += len(problems)
    out.write("GATE %s passed=%d failed=%d skipped=%d\n" % (stage, passed, failed, skipped))
    return passed, failed, skipped, problems


def self_test():
    junit = """<?xml version="1.0"?><testsuite>
<testcase name="A.passes" status="run"><system-out>ok</system-out></testcase>
<testcase name="B.fails" status="fail"><failure message="Failed"/></testcase>
<testcase name="Ipc.skips" status="notrun"><skipped message="SKIP_REGULAR_EXPRESSION_MATCHED"/>
<system-out>x.cpp:10: Skipped
cannot unshare: Operation not permitted

[  SKIPPED ] Ipc.skips (0 ms)</system-out></testcase>
<testcase name="Hw.skips" status="notrun"><skipped/><system-out>SKIP: set KINECT_HW=1</system-out></testcase>
<testcase name="browser" status="notrun"><skipped/><system-out>SKIP: chromium not installed</system-out></testcase>
</testsuite>"""
    labels = {"Ipc.skips": ["unit_must_run"], "Hw.skips": ["hardware"], "browser": ["must_run", "needs_host"]}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "j.xml")
        with open(path, "w", encoding="utf-8") as f:
            f.write(junit)
        found = results(path)
    devnull = open(os.devnull, "w", encoding="utf-8")
    manifest = [("^Ipc\\.", "RouDi"), ("^Dds\\.", "Cyclone DDS")]
    p, f, s, problems = gate("release", labels, found, manifest, True, devnull)
    checks = [
        (p, 1, "passed in CI"), (f, 1 + 3, "failed in CI: one failure, two must-run skips, one missing"),
        (s, 3, "skipped in CI"),
        (any("Ipc.skips" in x and "Operation not permitted" in x for x in problems), True, "reason named"),
        (any("missing: ^Dds" in x and "Cyclone" in x for x in problems), True, "missing test named"),
        (any("Hw.skips" in x for x in problems), False, "hardware never gates"),
    ]
    p, f, s, problems = gate("release", labels, found, manifest, False, devnull)
    checks += [(f, 1, "outside CI only real failures count"), (problems, [], "no gate failure outside CI")]
    bad = [(what, got, want) for got, want, what in checks if got != want]
    for what, got, want in bad:
        print("self-test: %s: got %r, want %r" % (what, got, want))
    print("self-test: %d of %d checks hold" % (len(checks) - len(bad), len(checks)))
    return 1 if bad else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stage")
    parser.add_argument("--build")
    parser.add_argument("--junit")
    parser.add_argument("--manifest")
    parser.add_argument("--ci", action="store_true", help="must-run skips and absences fail")
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    found = results(args.junit) if os.path.exists(args.junit) else []
    gate(args.stage, labels_by_test(args.build), found, manifest_entries(args.manifest, args.stage), args.ci,
         sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
