"""`orthoflow arm list|info|state|home|retract|move|fingers|stop|reset|limits --sim`: the JACO
driver's commands on the simulated arm (no USB on this machine; it runs in real time), their
refusals, the limits file, and the stop that every signal and a second process reach, latched
until `arm reset` (docs/SAFETY.md)."""
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

from cli_check import expect, run

cli = sys.argv[1]
EXIT_USAGE = 106
EXIT_BAD_INPUT = 2
EXIT_UNREACHABLE = 31
# The arm's holder lock and latch live here for this test alone (drivers/jaco/arm_state_dir.hpp).
state_dir = tempfile.mkdtemp(prefix="orthoflow_arm_cli_")
os.environ["ORTHOFLOW_ARM_STATE_DIR"] = state_dir

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

# A stop with no holder opens the arm itself, halts it and latches; motion is refused until reset.
p = run(cli, "arm", "stop", "--sim")
expect("no process held the arm" in p.stdout and "latched" in p.stdout, f"stop: {p.stdout}")
p = run(cli, "arm", "move", "--sim", "--joints", ",".join(map(str, target)), code=1)
expect("latched" in p.stderr and "orthoflow arm reset" in p.stderr, f"latched: {p.stderr}")
expect("cleared" in run(cli, "arm", "reset", "--sim").stdout, "reset")
expect("no stop is latched" in run(cli, "arm", "reset", "--sim").stdout, "reset twice")

# An arm that never initialises: HOME gives up after --timeout, with the button released; fingers
# are refused at once (a NOINIT arm ignores them).
p = run(cli, "arm", "home", "--sim", "--sim-start", "noinit", "--sim-never-init", "--timeout", "1",
        code=1)
expect("timed out" in p.stderr, f"never init: {p.stderr}")
t0 = time.monotonic()
p = run(cli, "arm", "fingers", "--sim", "--sim-start", "noinit", "close", code=1)
expect("invalid_state" in p.stderr and time.monotonic() - t0 < 5, f"fingers in noinit: {p.stderr}")

# The user's report: a 5 mm plate across a 90 degree base turn is refused, and nothing moves.
p = run(cli, "arm", "move", "--sim", "--joints", "185,167.5,57.5,240,82.5,75",
        "--keep-out", "0.2,-0.025,0.4,0.5,-0.020,0.6,plate", code=EXIT_USAGE)
expect("keep-out box 'plate'" in p.stderr, f"plate: {p.stderr}")
p = run(cli, "arm", "move", "--sim", "--joints", "185,167.5,57.5,240,82.5,75",
        "--keep-out", "0.5,-0.020,0.6,0.2,-0.025,0.4,plate", code=EXIT_USAGE)
expect("inverted" in p.stderr, f"inverted box: {p.stderr}")

# The limits: the defaults keep the table and the base out; a file that widens the hardware's
# range is refused naming the key.
limits = run(cli, "arm", "limits", "--sim", "--json").stdout
names = [b["name"] for b in json.loads(limits)["keep_out"]]
expect(names == ["table", "base"], f"limits: {limits}")
wide = os.path.join(state_dir, "wide.yaml")
with open(wide, "w") as f:
    f.write("speed_deg_s: 90\n")
p = run(cli, "arm", "move", "--sim", "--limits", wide, "--joints", ",".join(map(str, target)),
        code=EXIT_BAD_INPUT)
expect("speed_deg_s" in p.stderr, f"wide limits: {p.stderr}")

# The camera's keep-out: a motion command without robot frames says it has none; with them, it is
# placed (and `arm limits --frames` lists it).
p = run(cli, "arm", "move", "--sim", "--joints", ",".join(map(str, home)))
expect("no camera keep-out" in p.stderr, f"camera warning: {p.stderr}")
frames = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "config",
                      "robot_frames_synthetic.yaml")
p = run(cli, "arm", "move", "--sim", "--frames", frames, "--joints", ",".join(map(str, home)))
expect("no camera keep-out" not in p.stderr, f"camera placed: {p.stderr}")
placed = json.loads(run(cli, "arm", "limits", "--sim", "--json", "--frames", frames).stdout)
expect("camera" in [b["name"] for b in placed["keep_out"]], f"limits --frames: {placed}")


def moving_arm():
    """A long move on the simulated arm, in the background, holding the arm."""
    far = list(home)
    far[0] += 80
    proc = subprocess.Popen([cli, "arm", "move", "--sim", "--speed", "0.5", "--joints",
                             ",".join(map(str, far))],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.8)
    return proc


# Every signal to the holder halts the arm in place (no retreat) and latches the stop.
for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT):
    proc = moving_arm()
    proc.send_signal(sig)
    out, errs = proc.communicate(timeout=10)
    expect(proc.returncode == 1 and f"stopped ({sig.name})" in errs and "latched" in errs,
           f"{sig.name}: {proc.returncode} {errs}")
    expect(sig.name in run(cli, "arm", "reset", "--sim").stdout, f"reset after {sig.name}")

# A second process: `arm stop` reaches the holder (no RouDi here: by SIGTERM), says the arm was
# moving; a second holder is refused, naming the first.
proc = moving_arm()
p = run(cli, "arm", "move", "--sim", "--joints", ",".join(map(str, target)), code=1)
expect("not free" in p.stderr and "held by pid" in p.stderr, f"two holders: {p.stderr}")
p = run(cli, "arm", "stop", "--sim", "--json")
stop = json.loads(p.stdout)
expect(stop["stopped"] and stop["was_moving"] and stop["holder_pid"] == proc.pid, f"stop: {stop}")
out, errs = proc.communicate(timeout=10)
expect(proc.returncode == 1 and "latched" in errs, f"stopped holder: {errs}")
run(cli, "arm", "reset", "--sim")

# No arm on this machine's USB: a clear message.
p = run(cli, "arm", "info", code=None)
expect(p.returncode != 0 and ("no Kinova JACO found" in p.stderr or "libusb" in p.stderr),
       f"info (usb): {p.stderr}")
print("ok")
