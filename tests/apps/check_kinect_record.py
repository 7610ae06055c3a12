"""`orthoflow kinect record DIR` and `orthoflow run --source replay:DIR` (issue 18): a recording of
the simulated camera in fakenect's format, replayed through the same conversion as the live camera;
an existing recording is never overwritten; a damaged record is a frame error naming the file; a
FIFO in its place is refused at once; a recording none of whose records reads fails the run."""
import json
import os
import re
import shutil
import struct
import sys

from cli_check import expect, run

cli, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
rec = os.path.join(work, "rec")

p = run(cli, "kinect", "record", rec, "--sim", "--frames", "15")
expect("recorded 15 depth and 15 colour frames and " in p.stdout, f"record: {p.stdout}")
index = open(os.path.join(rec, "INDEX.txt")).read().split()
depth = [n for n in index if n.startswith("d-")]
colour = [n for n in index if n.startswith("r-")]
accel = [n for n in index if n.startswith("a-")]
expect(len(depth) == 15 and len(colour) == 15, f"index: {index[:4]}")
# The accelerometer, read by the driver about every 100 ms: 12-byte freenect_raw_tilt_state dumps,
# one before the first frame, reading 1 g (819 counts) pitched like the simulated scene.
expect(len(accel) >= 2 and index[0].startswith("a-"), f"accelerometer records: {index[:4]}")
expect(f"and {len(accel)} accelerometer records" in p.stdout, f"record: {p.stdout}")
with open(os.path.join(rec, accel[0]), "rb") as f:
    data = f.read()
expect(len(data) == 12, f"a- record: {len(data)} bytes")
ax, ay, az, tilt, status = struct.unpack("<hhhbxi", data)
expect(abs((ax * ax + ay * ay + az * az) ** 0.5 - 819) < 5 and az < -300, f"a- record: {ax} {ay} {az}")
with open(os.path.join(rec, depth[0]), "rb") as f:
    data = f.read()
expect(data.startswith(b"P5 640 480 65535\n") and len(data) == 17 + 640 * 480 * 2, "d- record")
values = struct.unpack("<%dH" % (640 * 480), data[17:])
expect(max(values) <= 2047 and values.count(2047) < len(values), "d-: 11-bit disparities")
with open(os.path.join(rec, colour[0]), "rb") as f:
    expect(f.read(15) == b"P6 640 480 255\n", "r- record")
device = json.load(open(os.path.join(rec, "device.json")))
expect(abs(device["reg_info"]["zero_plane_info"]["reference_pixel_size"] - 0.1042) < 1e-6 and
       device["const_shift"] == 200 and len(device["reg_info"]) == 26, f"device.json: {device}")
# Device timestamps: 60 MHz, whole frames apart (2,000,000 ticks at 30 Hz). A frame the recorder
# did not take in time (a loaded machine, a sanitizer build) is a gap of whole frames, and every
# such frame is counted in the camera's health line: nothing is lost silently.
ticks = [int(n.split("-")[2].split(".")[0]) for n in depth]
expect(all(b > a and (b - a) % 2000000 == 0 for a, b in zip(ticks, ticks[1:])), f"timestamps: {ticks}")
missed = sum((b - a) // 2000000 - 1 for a, b in zip(ticks, ticks[1:]))
health = re.search(r"(\d+) dropped, (\d+) not taken in time", p.stdout)
expect(health is not None, f"no camera health line: {p.stdout}")
expect(missed <= int(health.group(1)) + int(health.group(2)),
       f"{missed} frames missing from the recording but not counted: {p.stdout} {ticks}")

# Never over an existing recording.
p = run(cli, "kinect", "record", rec, "--sim", "--frames", "2", code=106)
expect("already holds a recording" in p.stderr, p.stderr)

# Replay at the recorded pace (15 frames ~ 0.5 s) and as fast as possible.
p = run(cli, "run", "--source", "replay:" + rec, "--threads", "1")
expect("15 processed" in p.stdout and "15 with a table" in p.stdout, f"replay: {p.stdout}")
p = run(cli, "run", "--source", "replay:" + rec, "--rate", "max", "--threads", "1",
        "--json-out", os.path.join(work, "replay.jsonl"))
expect("15 processed" in p.stdout, f"replay max: {p.stdout}")
rows = [json.loads(line) for line in open(os.path.join(work, "replay.jsonl"))]
expect(all(r["gravity"] == "sensor" and r["table_reason"] == "accepted" and r["tilt_deg"] < 2
           for r in rows), f"replay gravity: {rows[0]}")

# A truncated record: that frame is an error naming the file, the others run.
bad = os.path.join(work, "bad")
shutil.copytree(rec, bad)
with open(os.path.join(bad, depth[3]), "r+b") as f:
    f.truncate(1000)
p = run(cli, "run", "--source", "replay:" + bad, "--rate", "max", "--threads", "1", code=None)
expect("15 processed" in p.stdout and "1 with an error" in p.stdout, f"bad replay: {p.stdout}")
expect(depth[3] in p.stderr, f"bad replay names the file: {p.stderr}")
# A FIFO where a record should be: refused at once as not a regular file (never waited on), the
# other frames run (issue 52, item 8).
fifo = os.path.join(work, "fifo")
shutil.copytree(rec, fifo)
os.remove(os.path.join(fifo, depth[5]))
os.mkfifo(os.path.join(fifo, depth[5]))
p = run(cli, "run", "--source", "replay:" + fifo, "--rate", "max", "--threads", "1", timeout=60)
expect("15 processed" in p.stdout and "1 with an error" in p.stdout, f"fifo replay: {p.stdout}")
expect("is not a regular file" in p.stderr, f"fifo replay says why: {p.stderr}")
# A recording none of whose records reads: the run has no result and fails (issue 52, item 9).
dead = os.path.join(work, "dead")
shutil.copytree(rec, dead)
for name in depth:
    with open(os.path.join(dead, name), "r+b") as f:
        f.truncate(1000)
p = run(cli, "run", "--source", "replay:" + dead, "--rate", "max", "--threads", "1", code=2)
expect("no frame could be used (15 of 15 failed)" in p.stderr, f"dead replay: {p.stderr}")
# A directory without a recording.
p = run(cli, "run", "--source", "replay:" + work, code=None)
expect(p.returncode != 0 and "INDEX.txt" in p.stderr, f"no index: {p.stderr}")
print("ok")
