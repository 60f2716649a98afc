#!/usr/bin/env python3
"""A planner that breaks forkbench's protocol in the way argv[1] names, for the tests.

Modes: good, crash, hang, bad_json, nan, off_start, off_goal, curvature, wrong_version,
silent_hello, crash_once (crashes on its first plan if the marker file argv[2] does not
exist yet, then behaves), and the hostile ones:
- deaf: answers the hello, then stops reading (a large request blocks forkbench's write);
- chatty: answers, then leaves a child writing 1 KB lines to stdout forever;
- forks_sleeper: answers, leaving a child `sleep argv[3]` behind;
- ignores_eof: answers, and keeps running after its input closes;
- exit_child_holds_stdout: leaves a child holding stdout, says "bye" on stderr, exits 7;
- exit_mid_line: writes half an answer, says "oops" on stderr, exits 3.
"""
import json
import math
import os
import sys

mode = sys.argv[1]


def straight(req):
    """A straight-then-arc-free path: the start pose moved along its heading to the goal."""
    s, g = req["start"], req["goal"]
    n = max(2, int(math.hypot(g["x_m"] - s["x_m"], g["y_m"] - s["y_m"]) / 0.01) + 1)
    out = []
    for i in range(n):
        t = i / (n - 1)
        x = s["x_m"] + t * (g["x_m"] - s["x_m"])
        y = s["y_m"] + t * (g["y_m"] - s["y_m"])
        out.append([0.0, x, y, math.atan2(g["y_m"] - s["y_m"], g["x_m"] - s["x_m"]), 0.0])
    for i in range(1, n):
        out[i][0] = out[i - 1][0] + math.hypot(out[i][1] - out[i - 1][1], out[i][2] - out[i - 1][2])
    return out


def spawn(argv):
    """A child in the planner's process group that keeps its stdout."""
    import subprocess
    return subprocess.Popen(argv, stdin=subprocess.DEVNULL)


def hostile(req):
    """The hostile modes' behaviour around a good answer."""
    good = json.dumps({"type": "path", "id": req["id"], "samples": straight(req)})
    if mode == "chatty":
        print(good, flush=True)
        spawn([sys.executable, "-c", "import sys\nwhile True: sys.stdout.write('x' * 1000 + '\\n')"])
        return None
    if mode == "forks_sleeper":
        spawn(["sleep", sys.argv[3]])
    if mode == "exit_child_holds_stdout":
        spawn(["sleep", "1000"])
        sys.stderr.write("bye\n")
        sys.stderr.flush()
        os._exit(7)
    if mode == "exit_mid_line":
        sys.stdout.write(good[: len(good) // 2])
        sys.stdout.flush()
        sys.stderr.write("oops\n")
        sys.stderr.flush()
        os._exit(3)
    return good


def answer(req):
    if mode in ("chatty", "forks_sleeper", "exit_child_holds_stdout", "exit_mid_line", "ignores_eof"):
        return hostile(req)
    samples = straight(req)
    if mode == "crash" or (mode == "crash_once" and not os.path.exists(sys.argv[2])):
        if mode == "crash_once":
            open(sys.argv[2], "w").close()
        sys.stderr.write("planner: simulated segfault\n")
        sys.stderr.flush()
        os._exit(139)
    if mode == "hang":
        while True:
            pass
    if mode == "bad_json":
        return "{this is not json"
    if mode == "nan":
        samples[3][2] = float("nan")
        return json.dumps({"type": "path", "id": req["id"], "samples": samples}).replace("NaN", "NaN")
    if mode == "off_start":
        for p in samples:
            p[1] += 0.5
    if mode == "off_goal":
        samples = samples[: len(samples) // 2]
    if mode == "curvature":
        for p in samples:
            p[4] = 5.0
    return json.dumps({"type": "path", "id": req["id"], "samples": samples})


for line in sys.stdin:
    msg = json.loads(line)
    if msg["type"] == "hello":
        if mode == "silent_hello":
            continue
        version = 99 if mode == "wrong_version" else 1
        print(json.dumps({"type": "hello", "protocol": "forkbench-planner", "version": version}), flush=True)
        if mode == "deaf":
            import time
            time.sleep(1000)
    else:
        out = answer(msg)
        if out is not None:
            print(out, flush=True)
if mode == "ignores_eof":
    import time
    time.sleep(1000)
