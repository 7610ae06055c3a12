"""Shared helpers of the CLI check scripts in tests/apps: run the binary, check a condition."""
import signal
import subprocess
import sys


def run(cli, *args, code=0, timeout=None):
    """Runs `cli args...`; exits the check with the output when the exit code is not @p code (a run
    past @p timeout seconds raises subprocess.TimeoutExpired, failing the check)."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True, timeout=timeout)
    if code is not None and p.returncode != code:
        sys.exit(f"FAIL: {' '.join(map(str, args))}: exit {p.returncode}, wanted {code}\n"
                 f"stdout: {p.stdout}\nstderr: {p.stderr}")
    return p


def expect(condition, what):
    if not condition:
        sys.exit(f"FAIL: {what}")


def start_ui_run(cli, graph, db, token_file, frames=9000):
    """Starts `orthoflow run --graph GRAPH --rate 30 --db DB --ui 127.0.0.1:0 --ui-token-file F`
    and returns (process, base URL) once it printed its URL; the URL is None when it never did.
    The default 9000 frames at 30 Hz outlast a check, which stops the run with stop_run."""
    robot = subprocess.Popen([cli, "run", "--graph", str(graph), "--frames", str(frames), "--rate", "30",
                              "--db", str(db), "--ui", "127.0.0.1:0", "--ui-token-file", str(token_file)],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    for line in robot.stdout:
        if line.startswith("ui: http://"):
            return robot, line.split()[1].split("?")[0].rstrip("/")
    return robot, None


def stop_run(robot, check=True):
    """Stops a run with SIGINT (killed after 60 s) and returns its output; with @p check, a run that
    did not stop cleanly with exit 0 fails the check."""
    robot.send_signal(signal.SIGINT)
    try:
        out, _ = robot.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        robot.kill()
        out, _ = robot.communicate()
        expect(not check, f"run did not stop within 60 s of SIGINT: {out[-3000:]}")
    expect(not check or robot.returncode == 0, f"run exited {robot.returncode}: {out[-3000:]}")
    return out
