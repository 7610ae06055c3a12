"""Every output of every command either arrives or the exit says it did not (issue 52, item 12).

Each file option (--out, --png, --json FILE, --labels-out, --ground-truth, --truth, --plot,
--telemetry-json) is pointed at /dev/full (a device whose writes fail with ENOSPC) and at a path
under a regular file (ENOTDIR: unwritable even for root); standard output is sent to /dev/full for
every command that prints an answer. Each must exit non-zero, name what failed on stderr, never
die of a signal, and never replace /dev/full with a regular file. A path that is a device but
writable (/dev/null) is written into: the command succeeds and the device stays a device.

usage: check_output_failures.py ORTHOFLOW SHARED_DIR WORK_DIR
"""
import os
import shutil
import stat
import subprocess
import sys

from cli_check import expect

cli, shared, work = sys.argv[1], sys.argv[2], sys.argv[3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
objects = f"{shared}/data/objects"
scene = f"{shared}/data/scenes/test31.pcd"
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
a_file = f"{work}/a_file"
with open(a_file, "w") as f:
    f.write("not a directory\n")
frames = f"{work}/frames"  # one labelled frame for evaluate-segmentation
os.makedirs(frames)
first_frame = sorted(p for p in os.listdir(f"{shared}/data/mosd_learn") if p.endswith(".pcd"))[0]
shutil.copy(f"{shared}/data/mosd_learn/{first_frame}", frames)
views = f"{work}/views"
subprocess.run([cli, "synth-dataset", "--out", views, "--categories", "mug,bowl", "--instances", "1",
                "--views", "2", "--seed", "1"], check=True, capture_output=True)


def device_intact():
    return stat.S_ISCHR(os.stat("/dev/full").st_mode) and stat.S_ISCHR(os.stat("/dev/null").st_mode)


def run(args, stdout=subprocess.DEVNULL):
    p = subprocess.run([cli, *args], stdout=stdout, stderr=subprocess.PIPE, text=True, timeout=300)
    return p.returncode, p.stderr


def refused(args, what, stdout=subprocess.DEVNULL, mention=None):
    rc, err = run(args, stdout)
    if os.environ.get("SHOW"):
        print(rc, what, "|", err.strip().splitlines()[-1] if err.strip() else "")
    expect(rc > 0, f"{what}: {' '.join(args)} exited {rc}, wanted a failure\nstderr: {err[-800:]}")
    expect(mention is None or mention in err,
           f"{what}: stderr does not name '{mention}': {err[-800:]}")
    expect(device_intact(), f"{what}: /dev/full or /dev/null is no longer a character device")


expect(device_intact(), "this machine's /dev/full and /dev/null are character devices")

# File outputs: '@' is the output path under test.
file_cases = [
    ["describe", f"{objects}/bowl.pcd", "--png", "@"],
    ["synth", "--objects", "2", "--seed", "1", "--out", "@"],
    ["synth", "--objects", "2", "--seed", "1", "--out", f"{work}/s.pcd", "--ground-truth", "@"],
    ["segment", scene, "--labels-out", "@"],
    ["bench", "latency", "--frames", "3", "--rate", "max", "--json", "@"],
    ["bench", "latency", "--frames", "3", "--rate", "max", "--plot", "@"],
    ["calibrate", "simulate-samples", "--count", "8", "--out", "@"],
    ["calibrate", "simulate-samples", "--count", "8", "--out", f"{work}/samples.jsonl", "--truth", "@"],
    ["graph", "run", f"{root}/graphs/tabletop.yaml", "--frames", "3", "--json", "@"],
    ["dictionary", "build", "--from", views, "--words", "4", "--out", "@"],
    ["run", "--frames", "3", "--rate", "max", "--json-out", "@"],
    ["run", "--frames", "3", "--rate", "max", "--telemetry-json", "@"],
    ["evaluate-segmentation", "--dataset", frames, "--quiet", "--out", "@"],
    ["evaluate-segmentation", "--dataset", frames, "--quiet", "--png", "@"],
    ["evaluate", "--dataset", views, "--protocol", "cv10", "--learner", "instance", "--bins", "5",
     "--runs", "1", "--folds", "2", "--no-cache", "--quiet", "--out", "@"],
    ["derive-views", f"{objects}/bowl.pcd", "--views", "2", "--out", "@"],
    ["image", "render", f"{root}/deploy/image/robot.yaml", "--arch", "amd64", "--out", "@"],
    ["kinect", "record", "--sim", "--frames", "2", "--no-colour", "@"],
]
for case in file_cases:
    for bad in ("/dev/full", f"{a_file}/out"):
        refused([bad if a == "@" else a for a in case], f"{case[0]} {bad}", mention=bad)

# /dev/null takes a file output: written into, the command succeeds, the device stays.
for case in (["synth", "--objects", "2", "--seed", "1", "--out", "/dev/null"],
             ["segment", scene, "--labels-out", "/dev/null"],
             ["bench", "latency", "--frames", "3", "--rate", "max", "--json", "/dev/null"]):
    rc, err = run(case)
    expect(rc == 0 and device_intact(), f"{' '.join(case)}: exit {rc}, {err[-500:]}")

# Standard output: an answer printed to a full device is a failed command.
stdout_cases = [
    ["info", f"{objects}/bowl.pcd", "--json"],
    ["info", f"{objects}/bowl.pcd"],
    ["describe", f"{objects}/bowl.pcd", "--json"],
    ["segment", scene, "--json"],
    ["synth-dataset", "--out", f"{work}/sd", "--categories", "mug", "--instances", "1", "--views", "1"],
    ["calibrate", "simulate-samples", "--count", "8", "--out", f"{work}/s2.jsonl"],
    ["evaluate-segmentation", "--dataset", frames, "--quiet"],
    ["bench", "latency", "--frames", "3", "--rate", "max"],
    ["graph", "run", f"{root}/graphs/tabletop.yaml", "--frames", "3", "--json", "-"],
    ["kinect", "list", "--sim"],
    ["--help"],
]
for case in stdout_cases:
    with open("/dev/full", "w") as full:
        refused(case, f"stdout of {case[0]}", stdout=full, mention="standard output")

print("ok")
