#!/usr/bin/env python3
"""forkbench's Hybrid-A* against OMPL's RRT* and BIT* over Reeds-Shepp curves, C++, same maps and pose pairs.

    python3 tools/ompl_rs_compare.py [--pairs N] [--forkbench PATH] [--json FILE] [--check]

OMPL is Debian's `libompl-dev` (1.5.2), driven by `tools/ompl_rs_bench.cpp` (built here with
g++; `libompl-dev g++` apt-installed when missing and run as root): `ReedsSheppStateSpace`
at the truck's turning radius (1 / 1.063 m), the path-length objective, motions checked
every 5 cm, a pose valid when the truck's chassis and forks (grown by the 0.15 m margin)
cover no blocked cell. forkbench plans the same pairs with `plan hybrid-astar` on the same
map file (its blocked cells merged into rectangles, checked with parry2d).

Maps: the warehouse and the narrow warehouse, rasterised at 5 cm (`forkbench map`). Pairs:
random poses (seeded) whose footprint is 0.3 m clear of every blocked cell, at least 5 m
apart, any heading. Times are each planner's own (map loaded before): forkbench's search;
OMPL's `solve` until its first solution (its intermediate-solution callback), then the same
planner continued to 1 s for the length it reaches.
"""
import argparse
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ompl_compare  # noqa: E402  (the toolchain check, the build and the percentile)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RADIUS_M = 1.0 / 1.0632  # the default truck: tan(1.0471) / 1.629
MARGIN_M = 0.15
BODY = (2.45, 1.2)  # chassis length and width, behind the fork root
FORKS = (1.6, 0.535 + 0.15)  # forks' length and the block both forks span


def read_map(yaml_path):
    """(free cells by row from the bottom, width, height, resolution, origin)."""
    meta, items, key = {}, [], None
    for line in open(yaml_path):
        if line.lstrip().startswith("-") and key == "origin":
            items.append(float(line.strip()[1:]))
        elif ":" in line:
            key, v = (t.strip() for t in line.split(":", 1))
            meta[key] = v
    res = float(meta["resolution"])
    if meta["origin"]:
        items = [float(v) for v in meta["origin"].strip("[]").split(",")]
    ox, oy = items[:2]
    data = open(os.path.join(os.path.dirname(yaml_path), meta["image"]), "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":  # a header comment runs to the end of its line
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    w, h = int(fields[1]), int(fields[2])
    pix = data[pos + 1:]
    free = [[pix[(h - 1 - r) * w + c] == 254 for c in range(w)] for r in range(h)]
    return free, w, h, res, (ox, oy)


def clear(m, x, y, th, pad):
    """Whether the truck at (x, y, th), grown by `pad`, covers no blocked cell centre."""
    free, w, h, res, (ox, oy) = m
    c, s = math.cos(th), math.sin(th)
    for length, width, ahead in [(BODY[0], BODY[1], -BODY[0] / 2), (FORKS[0], FORKS[1], FORKS[0] / 2)]:
        cx, cy = x + ahead * c, y + ahead * s
        hl, hw = length / 2 + pad + res * 0.71, width / 2 + pad + res * 0.71
        ex, ey = abs(hl * c) + abs(hw * s), abs(hl * s) + abs(hw * c)
        for row in range(max(0, int((cy - ey - oy) / res)), min(h, int((cy + ey - oy) / res) + 1)):
            for col in range(max(0, int((cx - ex - ox) / res)), min(w, int((cx + ex - ox) / res) + 1)):
                if free[row][col]:
                    continue
                px, py = ox + (col + 0.5) * res - cx, oy + (row + 0.5) * res - cy
                if abs(px * c + py * s) <= hl and abs(-px * s + py * c) <= hw:
                    return False
    return True


def pairs(m, n, seed):
    free, w, h, res, (ox, oy) = m
    rng = random.Random(seed)

    def pose():
        while True:
            p = (ox + rng.random() * w * res, oy + rng.random() * h * res, rng.uniform(-math.pi, math.pi))
            if clear(m, *p, 0.3):
                return p
    out = []
    while len(out) < n:
        a, b = pose(), pose()
        if math.hypot(a[0] - b[0], a[1] - b[1]) >= 5.0:
            out.append((a, b))
    return out


def forkbench_runs(exe, yaml_path, todo):
    out = []
    for a, b in todo:
        arg = lambda p: "%.4f,%.4f,%.4f" % (p[0], p[1], math.degrees(p[2]))
        r = subprocess.run([exe, "plan", "hybrid-astar", "--map", yaml_path, "--start", arg(a), "--goal", arg(b),
                            "--margin-m", str(MARGIN_M), "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            # Exit 3: the search ran and found no path (its JSON line says why); else an error.
            why = json.loads(r.stdout)["error"] if r.returncode == 3 else r.stderr.strip()
            out.append({"success": False, "time_s": None, "error": why})
            continue
        m = json.loads(r.stdout)["manoeuvre"]
        out.append({"success": True, "time_s": m["time_s"], "length_m": m["length_m"],
                    "cusps": len(m["cusps"]), "length_after_1s_m": None})
    return out


def ompl_runs(bench, yaml_path, planner, todo, timeout_s):
    lines = "".join("%r %r %r %r %r %r\n" % (*a, *b) for a, b in todo)
    cmd = [bench, yaml_path, planner, "1", str(RADIUS_M), str(MARGIN_M), *map(str, BODY), *map(str, FORKS),
           str(timeout_s)]
    out = [json.loads(l) for l in subprocess.run(cmd, input=lines, check=True, capture_output=True,
                                                 text=True).stdout.splitlines()]
    return out


def row(world, library, planner, runs, timeout_s):
    ok = [r for r in runs if r["success"]]
    med = lambda k: statistics.median(r[k] for r in ok) if ok and ok[0][k] is not None else None
    # A failure counts at the time the planner gave up (forkbench: its own error, at once).
    times = [r["time_s"] if r["time_s"] is not None else timeout_s for r in runs]
    return {"world": world, "library": library, "planner": planner, "success": len(ok), "pairs": len(runs),
            "time_median_ms": 1e3 * statistics.median(times), "time_p90_ms": 1e3 * ompl_compare.pct(times, 0.9),
            "length_median_m": med("length_m"), "cusps_median": med("cusps"),
            "length_after_1s_median_m": med("length_after_1s_m")}


def table(rows):
    f = lambda v, fmt: "–" if v is None else fmt % v
    lines = ["| world | library | planner | success | time to first solution, median / p90 | first length, median "
             "| cusps, median | length after 1 s, median |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['world']} | {r['library']} | {r['planner']} | {r['success']}/{r['pairs']} | "
                     f"{r['time_median_ms']:.1f} / {r['time_p90_ms']:.1f} ms | {f(r['length_median_m'], '%.2f m')} | "
                     f"{f(r['cusps_median'], '%g')} | {f(r['length_after_1s_median_m'], '%.2f m')} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout-s", type=float, default=5.0)
    ap.add_argument("--json", help="also write the rows to FILE")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 unless Hybrid-A* succeeds on at least as many pairs as each OMPL planner")
    ap.add_argument("--forkbench", default=os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "forkbench"))
    a = ap.parse_args()
    ompl_compare.ensure_ompl()
    tmp = tempfile.mkdtemp(prefix="ompl-rs-compare-")
    bench = ompl_compare.build_bench(tmp, "ompl_rs_bench")
    rows, short = [], []
    for world in ["warehouse", "warehouse-narrow"]:
        subprocess.run([a.forkbench, "map", os.path.join(ROOT, "worlds", world + ".toml"), "--out", tmp],
                       check=True, capture_output=True)
        yaml_path = os.path.join(tmp, world + ".yaml")
        todo = pairs(read_map(yaml_path), a.pairs, a.seed)
        fb = row(world, "forkbench", "hybrid-astar", forkbench_runs(a.forkbench, yaml_path, todo), a.timeout_s)
        rows.append(fb)
        for planner in ["rrtstar", "bitstar"]:
            om = row(world, "OMPL", planner, ompl_runs(bench, yaml_path, planner, todo, a.timeout_s), a.timeout_s)
            rows.append(om)
            if fb["success"] < om["success"]:
                short.append(f"{world}: hybrid-astar {fb['success']} < {planner} {om['success']}")
    print(table(rows))
    if a.json:
        json.dump(rows, open(a.json, "w"), indent=1)
    if a.check and short:
        sys.exit("Hybrid-A* succeeds less often than OMPL: " + "; ".join(short))


if __name__ == "__main__":
    main()
