#!/usr/bin/env python3
"""A planner that breaks forkbench's protocol in the way argv[1] names, for the tests.

Modes: good, crash, hang, bad_json, nan, off_start, off_goal, curvature, wrong_version,
silent_hello, crash_once (crashes on its first plan if the marker file argv[2] does not
exist yet, then behaves).
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


def answer(req):
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
    else:
        print(answer(msg), flush=True)
