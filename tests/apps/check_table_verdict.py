"""The table verdict (issue 50) on fakenect recordings made here, replayed with `orthoflow run
--source replay:DIR`: a wall is not a table when the accelerometer says the camera is level (no
level plane at all), a plane 15 degrees from level is refused as not level; the
same wall is a floor-like support when the accelerometer says the camera looks straight down; with
no accelerometer records the level test is skipped and the JSON says `gravity: none`; unusable
accelerometer readings (all zero) are skipped and counted; a small patch is too small; and the last
accepted table is held through two frames and no more; an accelerometer reading older than a second
is not trusted (gravity none, its age in `up_stale_ms`, counted as `up_stale`); a depth record listed
after a later one is skipped and counted."""
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


def recording(name, frames, accel, omit=(), period=1 / 30.0, accel_once=False):
    """frames: depth record bytes; accel: (x, y, z) counts written before every frame (before the
    first only, with accel_once), or None; omit: frame numbers the recorder "dropped" (gaps in the
    device timestamps); period: host seconds between frames."""
    d = os.path.join(work, name)
    os.makedirs(d)
    index = []
    for k, data in enumerate(frames):
        if k in omit:
            continue
        t, ticks = 1000.0 + k * period, 2000000 * (k + 1)
        if accel is not None and (k == 0 or not accel_once):
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
# Frames out of time order: INDEX.txt lists frame 3 before frame 2. Frame 2 is skipped and counted
# (and, missing from the replay, counted as a missing frame), never replayed backwards in time.
d = recording("out_of_order", [wall] * 6, DOWN)
lines = open(os.path.join(d, "INDEX.txt")).read().split()
depth = [k for k, n in enumerate(lines) if n.startswith("d-")]
lines[depth[2]], lines[depth[3]] = lines[depth[3]], lines[depth[2]]
open(os.path.join(d, "INDEX.txt"), "w").write("\n".join(lines) + "\n")
rows, p = replay(d)
expect(len(rows) == 5, f"out_of_order: {len(rows)} frames")
expect("depth_records 5, frames_missing 1, without_gravity 0, accel_skipped 0, out_of_order 1"
       in p.stdout + p.stderr, f"out_of_order: {p.stdout} {p.stderr}")
expect("1 depth records skipped: INDEX.txt lists them after a later one" in p.stderr,
       f"out_of_order stderr: {p.stderr}")

# A stale accelerometer: one reading before the first frame, frames 0.6 s apart. A reading older
# than the table node's max_up_age_ms (1000) is not trusted: gravity none, and the age is reported.
rows, p = replay(recording("stale", [wall] * 4, DOWN, period=0.6, accel_once=True))
expect([r["gravity"] for r in rows] == ["sensor", "sensor", "none", "none"], f"stale: {rows}")
expect("up_stale_ms" not in rows[1] and abs(rows[2]["up_stale_ms"] - 1205) <= 2 and
       abs(rows[3]["up_stale_ms"] - 1805) <= 2, f"stale ages: {rows}")
expect("up_stale 2" in p.stdout + p.stderr, f"stale counter: {p.stdout} {p.stderr}")
print("ok")
