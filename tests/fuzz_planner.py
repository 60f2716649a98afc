#!/usr/bin/env python3
"""An external planner whose answers are a good straight path, corrupted from argv[1]'s seed:
truncated lines, numbers replaced by NaN, huge or negative values, dropped keys, wrong
types, control characters, extra lines. For the fuzz test."""
import json
import math
import random
import sys

rng = random.Random(int(sys.argv[1]))


def straight(req):
    s, g = req["start"], req["goal"]
    n = max(2, int(math.hypot(g["x_m"] - s["x_m"], g["y_m"] - s["y_m"]) / 0.01) + 1)
    h = math.atan2(g["y_m"] - s["y_m"], g["x_m"] - s["x_m"])
    pts = [[0.0, s["x_m"] + i / (n - 1) * (g["x_m"] - s["x_m"]), s["y_m"] + i / (n - 1) * (g["y_m"] - s["y_m"]), h, 0.0] for i in range(n)]
    for i in range(1, n):
        pts[i][0] = pts[i - 1][0] + math.hypot(pts[i][1] - pts[i - 1][1], pts[i][2] - pts[i - 1][2])
    return pts


def corrupt(msg):
    kind = rng.randrange(8)
    if kind == 0:
        text = json.dumps(msg)
        return text[: rng.randrange(len(text))]
    if kind == 1:
        p = rng.choice(msg["samples"])
        p[rng.randrange(5)] = rng.choice([float("nan"), 1e300, -1e300, -1.0, 0.0])
    elif kind == 2:
        del msg[rng.choice(["samples", "id", "type"])]
    elif kind == 3:
        msg["samples"] = rng.choice(["x", 3, None, [], [[1, 2]], [["a", 0, 0, 0, 0]]])
    elif kind == 4:
        msg["id"] = rng.choice([-1, 2**70, "0", None])
    elif kind == 5:
        msg["type"] = "error"
        msg["message"] = "\x1b[2K\r\x07" + "=cmd|' /C calc'!A0" + "\x00"
    elif kind == 6:
        msg["samples"] = msg["samples"][:: rng.choice([2, 50, 1000])]
    return json.dumps(msg).replace("NaN", rng.choice(["NaN", "1e999", "null"]))


for line in sys.stdin:
    req = json.loads(line)
    if req["type"] == "hello":
        print(json.dumps({"type": "hello", "protocol": "forkbench-planner", "version": 1}), flush=True)
        continue
    out = corrupt({"type": "path", "id": req["id"], "samples": straight(req)})
    if rng.randrange(6) == 0:
        print("garbage before the answer", flush=True)
    print(out, flush=True)
