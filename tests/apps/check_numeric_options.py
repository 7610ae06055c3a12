#!/usr/bin/env python3
"""Option-validation table test (issue 16): every numeric option of every command and subcommand,
found in the commands' own --help, is given hostile values; each must be refused at parse time with
CLI11's validation or conversion exit code (104/105) and a message naming the option, never a crash,
a hang or a run. A control value ("1") must pass the option's validation (the run then stops on the
extra argument the test appends, so no command ever starts)."""
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

BAD = ["nan", "inf", "-inf", "-1", "5abc", "1e400", ""]
EXTRA = "--zz-no-such-option"
OPTION = re.compile(r"^\s+(--[\w-]+)(?:,\s*-\w)?\s+(INT|UINT|FLOAT)\b")
SUB_HEADER = re.compile(r"^Subcommands:")
SUB = re.compile(r"^\s{2}([\w-]+)\s{2,}")


def run(cli, args, timeout=20):
    try:
        p = subprocess.run([cli] + args, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "timed out"
    return p.returncode, p.stdout + p.stderr


def walk(cli, path):
    """(path, option) for every numeric option below path, depth first."""
    _, text = run(cli, path + ["--help"])
    found, in_subs = [], False
    for line in text.splitlines():
        if SUB_HEADER.match(line):
            in_subs = True
            continue
        m = OPTION.match(line)
        if m and not in_subs:
            found.append((path, m.group(1)))
        s = SUB.match(line)
        if in_subs and s:
            found += walk(cli, path + [s.group(1)])
    return found


def check(cli, path, option):
    """The failures of one option: every hostile value refused, the control value accepted."""
    failures = []
    for value in BAD:
        rc, out = run(cli, path + [option, value, EXTRA])
        if rc not in (104, 105) or option not in out:
            failures.append(f"{' '.join(path)} {option} '{value}': exit {rc}: {out.strip()[:160]}")
    rc, out = run(cli, path + [option, "1", EXTRA])
    if rc in (104, 105) and option in out and "range" not in out:
        failures.append(f"{' '.join(path)} {option} '1' refused: {out.strip()[:160]}")
    return failures


def main(cli):
    options = walk(cli, [])
    # Each run is a whole process start (slow under the sanitizers): a few at a time, in the table's
    # order when reported.
    with ThreadPoolExecutor(max_workers=min(4, os.cpu_count() or 1) * 2) as pool:
        results = list(pool.map(lambda po: check(cli, *po), options))
    failures = [f for r in results for f in r]
    print(f"numeric options checked: {len(options)} ({len(BAD)} hostile values each)")
    for f in failures:
        print("FAIL", f)
    if len(options) < 30:
        print("FAIL: fewer numeric options than the CLI has: the help parser is broken")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
