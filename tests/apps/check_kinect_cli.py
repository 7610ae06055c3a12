"""`orthoflow kinect list|info|stream|tilt|led|accel --sim` and `orthoflow run --source kinect-sim`:
the Kinect driver's commands on the simulated camera (no USB on this machine), and their errors."""
import json
import sys

from cli_check import expect, run

cli = sys.argv[1]

cams = json.loads(run(cli, "kinect", "list", "--sim", "--json").stdout)
expect(len(cams) == 1 and cams[0]["model"] == "1414" and cams[0]["motor"], f"list: {cams}")
expect(len(cams[0]["serial"]) == 16, "list: serial")
k4w = json.loads(run(cli, "kinect", "list", "--sim", "--sim-model", "k4w", "--json").stdout)
expect(k4w[0]["model"] == "k4w" and not k4w[0]["motor"], f"list k4w: {k4w}")

info = json.loads(run(cli, "kinect", "info", "--sim", "--json").stdout)
expect(abs(info["zero_plane"]["reference_pixel_size"] - 0.1042) < 1e-6, f"info: {info['zero_plane']}")
expect(abs(info["zero_plane"]["dcmos_rcmos_distance"] - 2.4) < 1e-6, "info: the 2.4 cm override")
expect(info["const_shift"] == 200 and len(info["reg_info"]) == 29, "info: const shift, reg info")
expect(info["depth_mm_at_raw"]["800"] == 1193, f"info: mm at 800: {info['depth_mm_at_raw']}")

# 1 % packet loss: every frame is delivered whole or degraded (holes marked), at 30 Hz.
s = json.loads(run(cli, "kinect", "stream", "--sim", "--sim-drop", "0.01", "--frames", "30",
                   "--json").stdout)
expect(s["frames_taken"] == 30, f"stream: {s}")
expect(25 <= s["fps"] <= 35, f"stream: {s['fps']} Hz")
expect(s["lost_packets"] > 0 and s["frames_degraded"] > 0, f"stream: loss not seen: {s}")
expect(s["frames_whole"] + s["frames_degraded"] == s["frames_delivered"], "stream: accounting")

# No camera with that serial: a clear error, not a hang.
p = run(cli, "kinect", "info", "--sim", "--serial", "NOPE", code=1)
expect("no camera with serial NOPE" in p.stderr, f"info --serial: {p.stderr}")
# A machine without a Kinect (this one has no USB at all): list says so and succeeds.
p = run(cli, "kinect", "list")
expect("no Kinect v1 camera found" in p.stdout or "kinect" in p.stdout, f"list (usb): {p.stdout}")

# The 1414 motor (`kinect tilt|led|accel`). Each --sim run starts level, on simulated time.
a = json.loads(run(cli, "kinect", "accel", "--sim", "--json").stdout)
expect(a["tilt_deg"] == 0 and a["status"] == "stopped", f"accel: {a}")
expect(abs(sum(g * g for g in a["accel_g"]) ** 0.5 - 1.0) < 0.01, f"accel: not 1 g: {a}")
t = json.loads(run(cli, "kinect", "tilt", "20", "--wait", "--sim", "--json").stdout)
expect(abs(t["tilt_deg"] - 20) <= 0.5 and t["status"] == "stopped", f"tilt --wait: {t}")
t = json.loads(run(cli, "kinect", "tilt", "-12.5", "--sim", "--json").stdout)
expect(t["status"] == "moving", f"tilt (no wait): {t}")
p = run(cli, "kinect", "tilt", "40", "--sim", code=106)
expect("limit of +-31" in p.stderr, f"tilt 40: {p.stderr}")
p = run(cli, "kinect", "tilt", "up", "--sim", code=106)
expect("not a finite number" in p.stderr, f"tilt up: {p.stderr}")
led = json.loads(run(cli, "kinect", "led", "blink-red-yellow", "--sim", "--json").stdout)
expect(led["led"] == "blink-red-yellow", f"led: {led}")
run(cli, "kinect", "led", "blue", "--sim", code=105)
p = run(cli, "kinect", "accel", "--sim", "--sim-model", "1473", code=1)
expect("not_supported" in p.stderr and "audio firmware" in p.stderr, f"accel 1473: {p.stderr}")
p = run(cli, "kinect", "led", "red", "--sim", "--serial", "NOPE", code=1)
expect("no camera with serial NOPE" in p.stderr, f"led --serial: {p.stderr}")

# The tabletop graph fed by the simulated camera through the driver: 30 frames, tables found.
import os
import tempfile
tele = os.path.join(tempfile.mkdtemp(), "telemetry.json")
p = run(cli, "run", "--source", "kinect-sim", "--frames", "30", "--threads", "1",
        "--telemetry-json", tele)
expect("30 processed" in p.stdout and "30 with a table" in p.stdout, f"run: {p.stdout}")
# The driver's own counters, in the table and in the telemetry, under the source node.
expect("source device: frames_delivered " in p.stdout, f"run: no device line: {p.stdout}")
device = json.load(open(tele))["nodes"][0]["device"]
expect(device["frames_delivered"] >= 30 and device["lost_packets"] == 0 and device["streaming"] == 1,
       f"telemetry device counters: {device}")
p = run(cli, "run", "--source", "kinect-sim:abc", "--frames", "3", code=None)
expect(p.returncode != 0 and "sim_seed" in p.stderr, f"run kinect-sim:abc: {p.stderr}")
print("ok")
