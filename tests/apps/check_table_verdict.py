"""The table verdict (issue 50) on fakenect recordings made here, replayed with `orthoflow run
--source replay:DIR`: a wall is not a table when the accelerometer says the camera is level (no
level plane at all), a plane 15 degrees from level is refused as not level; the
same wall is a floor-like support when the accelerometer says the camera looks straight down; with
no accelerometer records the level test is skipped and the JSON says `gravity: none`; unusable
accelerometer readings (all zero) are skipped and counted; a small patch is too small; and the last
accepted table is held through two frames and no more."""
import json
import math
import os
import shutil
import struct
import sys

from cli_check import expect, run

cli, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
W, H = 640, 480
WALL_RAW = 800  # about 1.14 m (libfreenect's approximation 1 / (3.3309 - 0.0030711 raw))
INVALID = 2047


def depth_record(patch=None):
    """A wall at one disparity over the whole frame, or only inside patch = (x0, y0, x1, y1)."""
    if patch is None:
        values = [WALL_RAW] * (W * H)
    else:
        x0, y0, x1, y1 = patch
        values = [INVALID] * (W * H)
        for y in range(y0, y1):
            values[y * W + x0:y * W + x1] = [WALL_RAW] * (x1 - x0)
    return b"P5 640 480 65535\n" + struct.pack("<%dH" % (W * H), *values)


def accel_record(x, y, z):
    return struct.pack("<hhhbxi", x, y, z, 0, 0)  # freenect_raw_tilt_state, 12 bytes


def recording(name, frames, accel, omit=()):
    """frames: depth record bytes; accel: (x, y, z) counts written before every frame, or None;
    omit: frame numbers the recorder "dropped" (gaps in the device timestamps)."""
    d = os.path.join(work, name)
    os.makedirs(d)
    index = []
    for k, data in enumerate(frames):
        if k in omit:
            continue
        t, ticks = 1000.0 + k / 30.0, 2000000 * (k + 1)
        if accel is not None:
            a = "a-%.6f-%d.dump" % (t - 0.005, ticks)
            open(os.path.join(d, a), "wb").write(accel_record(*accel))
            index.append(a)
        n = "d-%.6f-%d.pgm" % (t, ticks)
        open(os.path.join(d, n), "wb").write(data)
        index.append(n)
    open(os.path.join(d, "INDEX.txt"), "w").write("\n".join(index) + "\n")
    return d


def replay(d):
    out = os.path.join(work, os.path.basename(d) + ".jsonl")
    p = run(cli, "run", "--source", "replay:" + d, "--rate", "max", "--json-out", out)
    return [json.loads(line) for line in open(out)], p


wall = depth_record()
LEVEL = (0, 819, 0)       # the camera level: up is -y in the camera frame
DOWN = (0, 0, -819)       # the camera pitched 90 degrees down: up is -z, towards the camera

rows, _ = replay(recording("wall_level", [wall] * 6, LEVEL))
expect(len(rows) == 6, f"wall_level: {len(rows)} frames")
# With an up, RANSAC draws only near-level hypotheses: a wall gives no plane at all.
for r in rows:
    expect(r["table"] is False and r["table_reason"] == "no_plane" and r["gravity"] == "sensor",
           f"wall_level: {r}")
    expect(r["plane"] is None and r["objects"] == [], f"wall_level: {r}")

# A plane the verdict refuses as not level: the up says the camera is rolled 15 degrees, beyond the
# verdict's 10 but inside the 20 RANSAC draws from, while looking straight down at the floor.
roll = math.radians(15)
rows, _ = replay(recording("wall_rolled", [wall] * 3, (int(-819 * math.sin(roll)), 0,
                                                        int(-819 * math.cos(roll)))))
for r in rows:
    expect(r["table"] is False and r["table_reason"] == "not_level", f"wall_rolled: {r}")
    expect(abs(r["tilt_deg"] - 15.0) < 1.0 and r["objects"] == [], f"wall_rolled tilt: {r}")

rows, _ = replay(recording("wall_down", [wall] * 6, DOWN))
for r in rows:
    expect(r["table"] is True and r["table_reason"] == "accepted" and r["gravity"] == "sensor",
           f"wall_down: {r}")
    expect(r["tilt_deg"] < 2.0 and abs(r["support"]["height_m"] - 1.14) < 0.1, f"wall_down: {r}")

rows, _ = replay(recording("wall_no_accel", [wall] * 3, None))
for r in rows:
    expect(r["gravity"] == "none" and r["tilt_deg"] is None and r["table_reason"] == "accepted",
           f"wall_no_accel: {r}")

rows, p = replay(recording("wall_zero_accel", [wall] * 3, (0, 0, 0)))
expect(all(r["gravity"] == "none" for r in rows), f"zero accel: {rows[0]}")
expect("3 of 3 accelerometer records skipped" in p.stderr, f"zero accel stderr: {p.stderr}")

# A 60 x 60 pixel patch at 1.14 m is about 11 cm across: far below the 0.1 m^2 a table needs.
patch = depth_record((290, 210, 350, 270))
rows, _ = replay(recording("patch", [patch] * 3, DOWN))
for r in rows:
    expect(r["table"] is False and r["table_reason"] == "too_small", f"patch: {r}")

# Hysteresis: three good frames, then four too small: held, held, then refused.
rows, _ = replay(recording("hold", [wall] * 3 + [patch] * 4, DOWN))
reasons = [r["table_reason"] for r in rows]
expect(reasons == ["accepted"] * 3 + ["held", "held", "too_small", "too_small"], f"hold: {reasons}")
expect([r["table"] for r in rows] == [True] * 5 + [False] * 2, f"hold tables: {reasons}")
# Frames the recorder dropped are counted from the gaps in the device timestamps.
_, p = replay(recording("gap", [wall] * 8, DOWN, omit={2, 3, 6}))
expect("depth_records 5, frames_missing 3, without_gravity 0, accel_skipped 0" in p.stdout + p.stderr,
       f"gap: {p.stdout} {p.stderr}")
print("ok")
