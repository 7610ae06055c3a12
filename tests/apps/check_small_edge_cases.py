#!/usr/bin/env python3
"""The "smaller, same classes" items of issue 16, through the CLI, one sub-case per command.

segment   a 2-12 pixel wide organized strip of a Kinect-like table view finds the table as the same
          points unorganized do; --leaf is applied to organized frames (and says so); error counts
          print as integers; finite points outside the ROI are reported as such.
synth     synth-dataset refuses an empty --out and duplicate categories, writing nothing.
derive    derive-views refuses two inputs with one stem (naming both) and an input without finite
          points, before writing anything; a read-only output reports the real errno and the path.
evaluate  the teacher protocol on a one-category dataset is refused up front with the reason.
frames    --frames -1 is refused with a message that names the option and the value.

Usage: check_small_edge_cases.py ORTHOFLOW SHARED_DIR WORK_DIR CASE
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys

from cli_check import expect, run

NY, NZ = -math.sin(math.radians(50)), -math.cos(math.radians(50))


def write_pcd(path, points, width, height):
    with open(path, "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                f"WIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\n"
                "DATA ascii\n")
        for p in points:
            f.write(" ".join("nan" if math.isnan(c) else f"{c:.7g}" for c in p) + "\n")


def table_strip(u0, w, v0=140, h=340):
    """Pixels of a 640x480 pinhole view (f 525) of a table 1.1 m away, tilted 50 degrees."""
    d = -(NY * 0.35 + NZ * 1.1)
    out = []
    for v in range(v0, v0 + h):
        for u in range(u0, u0 + w):
            rx, ry = (u - 319.5) / 525.0, (v - 239.5) / 525.0
            s = -d / (NY * ry + NZ)
            out.append((s * rx, s * ry, s))
    return out


def segment(cli, work, shared):
    for w in (2, 3, 4, 5, 8):
        pts = table_strip(320 - w // 2, w)
        for organized in (True, False):
            path = os.path.join(work, f"strip{w}{'o' if organized else 'u'}.pcd")
            write_pcd(path, pts, w if organized else len(pts), 340 if organized else 1)
            j = json.loads(run(cli, "segment", path, "--json").stdout)
            n = j["plane"]["normal"]
            expect(abs(n[1] * NY + n[2] * NZ) > 0.999,
                   f"{w}-pixel strip ({'organized' if organized else 'unorganized'}): plane {n}")
    frame = os.path.join(shared, "data", "scenes", "test31.pcd")
    plain = json.loads(run(cli, "segment", frame, "--json").stdout)
    expect(plain["plane_input"] == {"kind": "pixel_sample", "stride": 4}, plain["plane_input"])
    fine = json.loads(run(cli, "segment", frame, "--json", "--leaf", "0.01").stdout)
    coarse = json.loads(run(cli, "segment", frame, "--json", "--leaf", "0.02").stdout)
    expect(fine["plane_input"] == {"kind": "voxel_grid", "leaf": 0.01}, fine["plane_input"])
    expect(fine["inliers"] > coarse["inliers"], "--leaf 0.01 and 0.02 give the same plane input")
    text = run(cli, "segment", frame, "--leaf", "0.02").stdout
    expect("plane input: voxel grid, leaf 0.02 m" in text, text)
    expect("--leaf replaces that sample" in run(cli, "segment", "--help").stdout, "--help")
    far = os.path.join(work, "far.pcd")
    write_pcd(far, [(0.01 * (i % 10), 0.01 * (i // 10), 5.0) for i in range(100)], 10, 10)
    err = run(cli, "segment", far, code=1).stderr
    expect("100 finite points, 0 inside the region of interest x [-1, 1] y [-1, 1] z [0.3, 2] m"
           in err, err)
    two = os.path.join(work, "two.pcd")  # 3 points within 1 mm: one voxel, too few for a plane
    write_pcd(two, [(0.0, 0.0, 1.0), (0.001, 0.0, 1.0), (0.0, 0.001, 1.0)], 3, 1)
    err = run(cli, "segment", two, code=1).stderr
    expect(re.search(r"\b1 finite points, need at least 3", err), err)
    for e in (err, run(cli, "segment", far, code=1).stderr):
        expect(not re.search(r"\d\.000000", e), f"a count printed as a float: {e}")


def synth(cli, work, shared):
    cwd = os.path.join(work, "cwd")
    os.makedirs(cwd)
    p = subprocess.run([cli, "synth-dataset", "--out", "", "--categories", "mug", "--instances", "1",
                        "--views", "1"], capture_output=True, text=True, cwd=cwd)
    expect(p.returncode == 106 and "output directory is an empty path" in p.stderr,
           f"--out '': exit {p.returncode}: {p.stderr}")
    expect(os.listdir(cwd) == [], f"--out '' wrote into the working directory: {os.listdir(cwd)}")
    out = os.path.join(work, "twice")
    err = run(cli, "synth-dataset", "--out", out, "--categories", "mug,bowl,mug", "--instances", 1,
              "--views", 2, code=106).stderr
    expect("category 'mug' is listed twice" in err, err)
    expect(not os.path.exists(out), "--categories mug,bowl,mug wrote views")
    text = run(cli, "synth-dataset", "--out", out, "--categories", "mug,bowl", "--instances", 1,
               "--views", 2).stdout
    written = sum(len(files) for _, _, files in os.walk(out))
    expect("= 4 views written" in text and written == 4, f"{text} ({written} files)")


def derive(cli, work, shared):
    bowl = os.path.join(shared, "data", "objects", "bowl.pcd")
    for d in ("a", "b"):
        os.makedirs(os.path.join(work, d))
        shutil.copy(bowl, os.path.join(work, d, "bowl.pcd"))
    out = os.path.join(work, "ds")
    a, b = os.path.join(work, "a", "bowl.pcd"), os.path.join(work, "b", "bowl.pcd")
    err = run(cli, "derive-views", a, b, "--out", out, code=106).stderr
    expect(f"{a} and {b} have the same stem 'bowl'" in err, err)
    expect(not os.path.exists(out), "derive-views wrote before refusing a repeated stem")
    empty = os.path.join(work, "empty.pcd")
    write_pcd(empty, [(math.nan,) * 3] * 50, 50, 1)
    err = run(cli, "derive-views", a, empty, "--out", out, code=2).stderr
    expect(f"{empty}: no finite points (50 points, all NaN or infinite)" in err, err)
    expect(not os.path.exists(out), "derive-views wrote before refusing an all-NaN input")
    # A read-only output: a read-only bind mount where a private mount namespace is allowed (root
    # ignores file modes), else a mode-555 directory (not root), else /sys (mkdir: EPERM).
    ro = os.path.join(work, "ro")
    os.makedirs(ro)
    target = os.path.join(ro, "ds")
    if os.geteuid() != 0:
        os.chmod(ro, 0o555)
        p = subprocess.run([cli, "derive-views", a, "--out", target], capture_output=True, text=True)
        want = "Permission denied"
    elif subprocess.run(["unshare", "-m", "true"], capture_output=True).returncode == 0:
        p = subprocess.run(["unshare", "-m", "sh", "-c",
                            f'mount --bind "{ro}" "{ro}" && mount -o remount,ro,bind "{ro}" && '
                            f'exec "{cli}" derive-views "{a}" --out "{target}"'],
                           capture_output=True, text=True)
        want = "Read-only file system"
    else:
        target = "/sys/orthoflow-derive-views-test"
        p = subprocess.run([cli, "derive-views", a, "--out", target], capture_output=True, text=True)
        want = "Operation not permitted"
    expect(p.returncode == 1 and f"cannot create {target}/bowl/bowl_0: {want}" in p.stderr,
           f"read-only output: exit {p.returncode}: {p.stderr}")
    text = run(cli, "derive-views", a, "--out", out, "--views", 3).stdout
    expect(text.strip() == f"{out}/bowl/bowl_0: 3 views", text)


def evaluate(cli, work, shared):
    ds, out = os.path.join(work, "ds"), os.path.join(work, "report")
    run(cli, "synth-dataset", "--out", ds, "--categories", "mug", "--instances", 2, "--views", 4)
    for protocol in ("teacher", "teacher-context"):
        p = run(cli, "evaluate", "--dataset", ds, "--protocol", protocol, "--runs", 1, "--out", out,
                "--no-cache", "--quiet", code=2)
        expect("too_few_categories: the" in p.stderr and "the dataset has 1" in p.stderr, p.stderr)
        expect(not os.path.exists(out), f"{protocol}: a report was started")
    err = run(cli, "evaluate", "--dataset", ds, "--protocol", "teacher", "--no-cache", "--quiet",
              "--out", out, code=2).stderr
    expect("the teacher protocol needs at least 2 categories, the dataset has 1 ('mug')" in err, err)


def frames(cli, work, shared):
    graphs = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "graphs")
    commands = [["run"], ["graph", "run", os.path.join(graphs, "tabletop.yaml")],
                ["ipc", "run", os.path.join(graphs, "perception.yaml")], ["ipc", "send"]]
    wanted = {"-1": "'-1' is negative (expected 0 or more)", "1.5": "'1.5' is not a whole number",
              "99999999999999999999": "'99999999999999999999' is too large (at most 9223372036854775807)"}
    for command in commands:
        help_text = run(cli, *command, "--help").stdout
        expect("--frames" in help_text, f"{command} has no --frames")
        for value, message in wanted.items():
            p = subprocess.run([cli, *command, "--frames", value], capture_output=True, text=True,
                               timeout=30)
            expect(p.returncode == 105 and f"--frames: {message}" in p.stderr,
                   f"{' '.join(command)} --frames {value}: exit {p.returncode}: {p.stderr}")


CASES = {"segment": segment, "synth": synth, "derive": derive, "evaluate": evaluate,
         "frames": frames}


def main():
    cli, shared, work, case = sys.argv[1:5]
    work = os.path.join(work, case)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    CASES[case](cli, work, shared)
    print(f"{case}: ok")


if __name__ == "__main__":
    main()
