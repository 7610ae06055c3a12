"""Shared helpers of the CLI check scripts in tests/apps: run the binary, check a condition."""
import subprocess
import sys


def run(cli, *args, code=0):
    """Runs `cli args...`; exits the check with the output when the exit code is not @p code."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    if code is not None and p.returncode != code:
        sys.exit(f"FAIL: {' '.join(map(str, args))}: exit {p.returncode}, wanted {code}\n"
                 f"stdout: {p.stdout}\nstderr: {p.stderr}")
    return p


def expect(condition, what):
    if not condition:
        sys.exit(f"FAIL: {what}")
