#!/usr/bin/env python3
"""Store round trip and killed imports through the CLI (issue 16, data loss 2 and 3).

1. A view with one stray point 1e30 m out (and one at the float limit) is taught, described with a
   finite frame and box (the far point left out), exported and imported into a fresh store: the
   round trip holds where it used to fail on `null`.
2. kill -9 at 25 moments during the import of a 300-label export: the store holds none of the
   labels or all of them, never a part; importing again then adds them or is refused as a repeat.

Usage: check_store_round_trip.py ORTHOFLOW OBJECTS_DIR WORK_DIR
"""
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import time


def run(cli, *args, ok=True):
    p = subprocess.run([cli, *args], capture_output=True, text=True)
    if ok and p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)} exited {p.returncode}: {p.stderr}")
    return p


def with_stray(src, dst, stray):
    data = open(src, "rb").read()
    header, body = data.split(b"DATA binary\n", 1)
    fields = dict(l.split(b" ", 1) for l in header.split(b"\n") if b" " in l and not l.startswith(b"#"))
    assert fields[b"FIELDS"] == b"x y z rgba", fields[b"FIELDS"]
    n = int(fields[b"POINTS"])
    head = (f"VERSION 0.7\nFIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH {n + 1}\n"
            f"HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n + 1}\nDATA binary\n").encode()
    open(dst, "wb").write(head + body[: 16 * n] + struct.pack("<fffI", *stray, 0))


def labels(cli, db):
    out = run(cli, "memory", "--db", db, "list").stdout
    return sorted(l.split("\t")[1] for l in out.splitlines() if l.strip())


def main():
    cli, objects, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    # 1. far points
    db, copy = os.path.join(work, "store"), os.path.join(work, "copy")
    for i, stray in enumerate([(1e30, 0.0, 0.0), (3.4e38, -3.4e38, 3.4e38)]):
        view = os.path.join(work, f"stray{i}.pcd")
        with_stray(os.path.join(objects, "bowl.pcd"), view, stray)
        d = json.loads(run(cli, "describe", view, "--json").stdout)
        if d["far_points"] != 1 or "far_points_dropped" not in d["flags"]:
            sys.exit(f"FAIL: the stray point of {view} was not left out: {d['far_points']} {d['flags']}")
        if any(v is None for v in d["bbox"] + d["frame"]) or max(d["bbox"]) > 1.0:
            sys.exit(f"FAIL: {view}: box {d['bbox']}")
        run(cli, "memory", "--db", db, "teach", f"stray{i}", view)
    export = os.path.join(work, "store.jsonl")
    run(cli, "memory", "--db", db, "export", export)
    run(cli, "memory", "--db", copy, "import", export)
    if labels(cli, copy) != ["stray0", "stray1"]:
        sys.exit(f"FAIL: round trip lost labels: {labels(cli, copy)}")
    # 2. killed imports: a 300-label export, made by importing a hand-written export of one view.
    line = open(export).read().splitlines()
    header, view_line = json.loads(line[0]), json.loads(line[1])
    header.pop("views", None)
    header.pop("categories", None)
    big = os.path.join(work, "big.jsonl")
    with open(big, "w") as f:
        f.write(json.dumps(header) + "\n")
        for k in range(300):
            view_line["label"] = f"label{k:03d}"
            f.write(json.dumps(view_line) + "\n")
    wanted = sorted(f"label{k:03d}" for k in range(300))
    # How long one import takes here (with its start-up), so the kills spread over all of it.
    probe = os.path.join(work, "probe")
    start = time.monotonic()
    run(cli, "memory", "--db", probe, "import", big)
    duration = time.monotonic() - start
    outcomes = {"none": 0, "all": 0}
    for attempt in range(25):
        target = os.path.join(work, f"killed{attempt}")
        run(cli, "memory", "--db", target, "teach", "base", os.path.join(objects, "bowl.pcd"))
        p = subprocess.Popen([cli, "memory", "--db", target, "import", big],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(duration * 1.2 * attempt / 25)
        p.send_signal(signal.SIGKILL)
        p.wait()
        got = [l for l in labels(cli, target) if l != "base"]
        if got == []:
            outcomes["none"] += 1
            run(cli, "memory", "--db", target, "import", big)
            again = [l for l in labels(cli, target) if l != "base"]
            if again != wanted:
                sys.exit(f"FAIL: attempt {attempt}: the import after the kill gave {len(again)} labels")
        elif got == wanted:
            outcomes["all"] += 1
            if run(cli, "memory", "--db", target, "import", big, ok=False).returncode == 0:
                sys.exit(f"FAIL: attempt {attempt}: a repeated import was not refused")
        else:
            sys.exit(f"FAIL: attempt {attempt}: a killed import left {len(got)} of 300 labels")
        shutil.rmtree(target)
    print(f"killed imports ({duration * 1000:.0f} ms each): {outcomes['none']} left nothing, "
          f"{outcomes['all']} completed, none partial")


if __name__ == "__main__":
    main()
