"""The CLI's thin client (apps/cmd_remote.cpp) against a running `orthoflow run --ui --db`: state,
ask, teach, undo, correct and forget over HTTP, each acknowledged; a bad label fails before any
request; a refused action exits 30, an unreachable robot 31; the token is needed when the server has
one; and what the client was told is stored is in the memory after the run.

usage: check_remote_cli.py ORTHOFLOW WORKDIR"""
import json
import os
import pathlib
import shutil
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "apps"))
from cli_check import expect, run, start_ui_run, stop_run  # noqa: E402

cli, work = sys.argv[1], pathlib.Path(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
db = work / "memory"
token = work / "ui.token"
token.write_text("remote-cli-token-0123456789\n")
# The embedded graph without its scripted instructor: every lesson in the memory is the client's.
graph = work / "tabletop.yaml"
source = pathlib.Path(__file__).resolve().parents[2] / "graphs" / "tabletop.yaml"
graph.write_text(source.read_text().replace("instructor: 1", "instructor: 0"))

robot, url = start_ui_run(cli, graph, db, token)
try:
    expect(url is not None, "run --ui printed no URL")
    auth = ["--url", url, "--token-file", token]

    # No token: the server refuses (401), the client says so and exits 30.
    p = run(cli, "state", "--url", url, code=30)
    expect("401" in p.stderr, f"no 401 without the token: {p.stderr}")

    deadline = time.time() + 60
    track = None
    while track is None and time.time() < deadline:
        doc = json.loads(run(cli, "state", *auth, "--json").stdout)
        for o in doc["objects"]:
            if o["described"] and not o["moving"] and not o["fragment"] and doc["frame"] >= 5:
                track = o["track"]
        time.sleep(0.1)
    expect(track is not None, "no described, still object within 60 s")
    expect(doc["durable"] is True, "run --db is not durable")
    human = run(cli, "state", *auth).stdout
    expect(f"track {track}" in human and "Unknown" in human, f"state table: {human}")

    p = run(cli, "ask", *auth, track)
    expect(p.stdout.startswith(f"track {track}: Unknown"), f"ask before teaching: {p.stdout}")

    # A bad label fails here, before a request (the server records no teach).
    p = run(cli, "teach", *auth, track, "mug\tcup", code=106)
    expect("control character" in p.stderr, p.stderr)
    events = json.loads(run(cli, "state", *auth, "--json").stdout)["events"]
    expect(all(e["action"] == "ask" for e in events), f"a refused label reached the server: {events}")

    p = run(cli, "teach", *auth, track, "alpha")
    expect(p.stdout.startswith(f"teach track {track} as \"alpha\"") and "(stored)" in p.stdout,
           p.stdout)
    taught = json.loads(run(cli, "teach", *auth, track, "alpha", "--json").stdout)
    expect(taught["outcome"] == "stored" and taught["views"] >= 1, f"second teach: {taught}")
    p = run(cli, "undo", *auth)
    expect(p.stdout.startswith(f"took back {taught['views']} view(s) of \"alpha\""), p.stdout)

    deadline = time.time() + 30
    answer = None
    while answer != "alpha" and time.time() < deadline:
        answer = json.loads(run(cli, "ask", *auth, track, "--json").stdout)["answer"]
        time.sleep(0.1)
    expect(answer == "alpha", f"ask after teaching: {answer}")
    expect("alpha" in run(cli, "ask", *auth, track).stdout, "ask prints the answer")

    p = run(cli, "correct", *auth, track, "beta")
    expect("as \"beta\": 1 view(s) (stored)" in p.stdout, p.stdout)
    p = run(cli, "forget", *auth, "beta")
    expect(p.stdout.startswith("forgot \"beta\" (stored)"), p.stdout)
    p = run(cli, "forget", *auth, "never-taught", code=30)
    expect("404" in p.stderr and "unknown_label" in p.stderr, p.stderr)
    p = run(cli, "teach", *auth, "4000000000", "gamma", code=30)
    expect("no_such_track" in p.stderr, p.stderr)
    refused = json.loads(run(cli, "teach", *auth, "4000000000", "gamma", "--json", code=30).stdout)
    expect(refused["outcome"] == "no_such_track", f"--json on a refusal: {refused}")
except BaseException:
    print(stop_run(robot, check=False)[-3000:], flush=True)  # the server's end, beside the failure
    raise
else:
    stop_run(robot)

# Usage errors and an unreachable robot.
run(cli, "teach", "--url", "https://127.0.0.1:1", "1", "x", code=106)
run(cli, "teach", "--url", "http://127.0.0.1:1/api", "1", "x", code=106)
run(cli, "ask", "--url", "http://127.0.0.1:1", "0", code=105)
run(cli, "undo", "--url", "http://127.0.0.1:1", "--timeout", "0", code=106)
p = run(cli, "undo", "--url", "http://127.0.0.1:1", code=31)
expect("cannot connect" in p.stderr, p.stderr)
os.environ["ORTHOFLOW_URL"] = "http://127.0.0.1:1"
run(cli, "state", code=31)

# The memory holds what the client was told: alpha's first teach (the second was undone), no beta.
listing = run(cli, "memory", "--db", db, "list").stdout
expect("alpha" in listing and "beta" not in listing, f"memory after the run: {listing}")
print("ok")
