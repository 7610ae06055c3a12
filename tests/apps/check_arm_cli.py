"""`orthoflow arm list|info|state|home|retract|move|fingers|stop --sim`: the JACO driver's commands on
the simulated arm (no USB on this machine; it runs in real time), their refusals and the e-stop."""
import json
import signal
import subprocess
import sys
import time

from cli_check import expect, run

cli = sys.argv[1]
EXIT_USAGE = 106

arms = json.loads(run(cli, "arm", "list", "--sim", "--json").stdout)
expect(len(arms) == 1, f"list: {arms}")
info = json.loads(run(cli, "arm", "info", "--sim", "--json").stdout)
expect(info["model"] == "jaco2" and info["serial"] == "PJ00650019161750", f"info: {info}")
expect(info["dsp_firmware"] == "5.2.0" and info["arm_state"] == "ready_standby", f"info: {info}")
v1 = json.loads(run(cli, "arm", "info", "--sim", "--sim-model", "v1", "--json").stdout)
expect(v1["model"] == "jaco_v1" and v1["dsp_firmware"].startswith("4."), f"info v1: {v1}")

state = json.loads(run(cli, "arm", "state", "--sim", "--json").stdout)
home = state["joints_deg"]
expect(len(home) == 6 and state["control"] == "idle" and not state["fault"], f"state: {state}")
follow = run(cli, "arm", "state", "--sim", "--follow", "--seconds", "0.5").stdout.splitlines()
expect(3 <= len(follow) <= 6 and all(l.startswith("joints") for l in follow), f"follow: {follow}")

# A joint move: arrives, in real time.
target = [q + d for q, d in zip(home, [10, -5, 5, 10, -5, 10])]
t0 = time.monotonic()
moved = json.loads(run(cli, "arm", "move", "--sim", "--json", "--speed", "1",
                       "--joints", ",".join(map(str, target))).stdout)
expect(all(abs(a - b) < 0.15 for a, b in zip(moved["joints_deg"], target)), f"move: {moved}")
expect(moved["last_stop"] == "reached" and time.monotonic() - t0 > 0.4, f"move: {moved}")

# Refusals name the limit and move nothing.
bad = list(home)
bad[1] = 330
p = run(cli, "arm", "move", "--sim", "--joints", ",".join(map(str, bad)), code=EXIT_USAGE)
expect("joint 2 target 330.00 deg is past its upper limit" in p.stderr, f"limit: {p.stderr}")
p = run(cli, "arm", "move", "--sim", "--joints", "1,2,3", code=EXIT_USAGE)
expect("needs 6" in p.stderr, f"--joints count: {p.stderr}")
p = run(cli, "arm", "move", "--sim", "--joints", "1,2,3,4,5,nan", code=EXIT_USAGE)
expect("not a finite number" in p.stderr, f"--joints nan: {p.stderr}")
x, y, z = state["position_m"]
box = f"{x - 0.05},{y - 0.05},{z - 0.05},{x + 0.05},{y + 0.05},{z + 0.05},camera"
p = run(cli, "arm", "move", "--sim", "--keep-out", box,
        "--joints", ",".join(map(str, target)), code=EXIT_USAGE)
expect("keep-out box 'camera'" in p.stderr, f"keep-out: {p.stderr}")
p = run(cli, "arm", "move", "--sim", "--pose", "0.85,0.85,0.3,0,0,0", code=EXIT_USAGE)
expect("unreachable" in p.stderr, f"unreachable: {p.stderr}")

# A Cartesian move to where the joint move went: IK nearest the current joints.
pose = moved["position_m"] + moved["theta_rad"]
reached = json.loads(run(cli, "arm", "move", "--sim", "--json", "--speed", "1",
                         "--pose", ",".join(map(str, pose))).stdout)
err = sum((a - b) ** 2 for a, b in zip(reached["position_m"], moved["position_m"])) ** 0.5
expect(err < 0.001, f"pose move: {err * 1000:.2f} mm off")

# HOME from power-up (NOINIT), RETRACT from HOME, fingers, stop.
h = json.loads(run(cli, "arm", "home", "--sim", "--sim-start", "noinit", "--json").stdout)
expect(h["arm_state"] == "ready_standby", f"home: {h}")
r = json.loads(run(cli, "arm", "retract", "--sim", "--json").stdout)
expect(r["arm_state"] == "retract_standby", f"retract: {r}")
p = run(cli, "arm", "retract", "--sim", "--sim-start", "normal", code=1)
expect("invalid_state" in p.stderr, f"retract from normal: {p.stderr}")
f = json.loads(run(cli, "arm", "fingers", "--sim", "close", "--json").stdout)
expect(all(v > 6000 for v in f["fingers"]), f"fingers: {f}")
p = run(cli, "arm", "fingers", "--sim", "9000,0,0", code=EXIT_USAGE)
expect("finger 1 target 9000.00" in p.stderr, f"fingers limit: {p.stderr}")
expect("stopped" in run(cli, "arm", "stop", "--sim").stdout, "stop")

# An arm that never initialises: HOME gives up after --timeout, with the button released.
p = run(cli, "arm", "home", "--sim", "--sim-start", "noinit", "--sim-never-init", "--timeout", "1",
        code=1)
expect("timed out" in p.stderr, f"never init: {p.stderr}")

# Ctrl-C during a move pulls the emergency stop.
far = list(home)
far[0] += 60
proc = subprocess.Popen([cli, "arm", "move", "--sim", "--joints", ",".join(map(str, far))],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(0.8)
proc.send_signal(signal.SIGINT)
out, errs = proc.communicate(timeout=10)
expect(proc.returncode == 1 and "emergency stop" in errs, f"SIGINT: {proc.returncode} {errs}")

# No arm on this machine's USB: a clear message.
p = run(cli, "arm", "info", code=None)
expect(p.returncode != 0 and ("no Kinova JACO found" in p.stderr or "libusb" in p.stderr),
       f"info (usb): {p.stderr}")
print("ok")
