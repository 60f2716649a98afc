#!/usr/bin/env python3
"""forkbench's PRM and RRT-Connect against OMPL's on the same occupancy grid, start and goal.

    python3 tools/ompl_compare.py [--runs N] [--forkbench PATH] [--timeout-s T]

Installs OMPL's Python bindings from PyPI (`pip install ompl`) when they are missing. The
map is the warehouse world rasterised at 5 cm with the obstacles grown by Luo's 0.815 m
(`forkbench map --inflate-m`), written as a ROS map; both libraries plan on that file:
forkbench with `plan prm|rrt-connect --map MAP.yaml --inflate-m 0`, OMPL in a 2-D
real-vector space whose validity checker reads the same cells. The leg is
`reproduce prm`'s: the charging station (3, 3) to the aisle before row 2b, bay 3.

Times: forkbench reports its own planning time (sampling, connection, search; the map is
loaded before); OMPL's is the wall time of `SimpleSetup.solve` to its first solution, which
includes its Python validity callbacks. Lengths are of the raw paths (no simplification).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
START, GOAL = (3.0, 3.0), (30.75, 10.25)
INFLATE_M = 0.815


def ensure_ompl():
    try:
        import ompl  # noqa: F401
        import yaml  # noqa: F401
    except ImportError:
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "ompl", "pyyaml"], check=True)


def read_map(yaml_path):
    """The ROS map: (free mask rows from the bottom, resolution, origin)."""
    import yaml
    meta = yaml.safe_load(open(yaml_path))
    res = float(meta["resolution"])
    origin = [float(v) for v in meta["origin"][:2]]
    pgm = open(os.path.join(os.path.dirname(yaml_path), meta["image"]), "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:  # magic, width, height, maxval, with `#` comments between
        while pgm[pos:pos + 1].isspace():
            pos += 1
        if pgm[pos:pos + 1] == b"#":
            pos = pgm.index(b"\n", pos)
            continue
        end = pos
        while not pgm[end:end + 1].isspace():
            end += 1
        fields.append(pgm[pos:end])
        pos = end
    w, h = int(fields[1]), int(fields[2])
    data = pgm[pos + 1:pos + 1 + w * h]
    # Rows are top first in the image; 254 is free in map_server's trinary export.
    free = [[data[(h - 1 - r) * w + c] == 254 for c in range(w)] for r in range(h)]
    return free, res, origin, w, h


def forkbench_runs(exe, yaml_path, planner, runs):
    out = []
    for seed in range(runs):
        cmd = [exe, "plan", planner, "--map", yaml_path, "--inflate-m", "0", "--nodes", "500",
               "--connect-m", "10", "--seed", str(seed), "--json",
               "--start", "%g,%g,0" % START, "--goal", "%g,%g,0" % GOAL]
        v = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        out.append((v["success"], v["timing_s"]["total"], v["length_m"]))
    return out


def ompl_runs(yaml_path, planner, runs, timeout_s):
    from ompl import base as ob, geometric as og
    free, res, origin, w, h = read_map(yaml_path)
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, origin[0]); bounds.setHigh(0, origin[0] + w * res)
    bounds.setLow(1, origin[1]); bounds.setHigh(1, origin[1] + h * res)
    space.setBounds(bounds)

    def valid(s):
        c, r = int((s[0] - origin[0]) / res), int((s[1] - origin[1]) / res)
        return 0 <= c < w and 0 <= r < h and free[r][c]

    out = []
    for _ in range(runs):
        ss = og.SimpleSetup(space)
        ss.setStateValidityChecker(valid)
        si = ss.getSpaceInformation()
        # Edges are checked every half cell, as fine as forkbench's cell walk.
        si.setStateValidityCheckingResolution(0.5 * res / space.getMaximumExtent())
        start, goal = space.allocState(), space.allocState()
        start[0], start[1] = START
        goal[0], goal[1] = GOAL
        ss.setStartAndGoalStates(start, goal)
        p = og.PRM(si) if planner == "prm" else og.RRTConnect(si)
        if planner == "rrt-connect":
            p.setRange(1.0)  # forkbench's RRT step
        ss.setPlanner(p)
        t0 = time.perf_counter()
        solved = ss.solve(timeout_s)
        t = time.perf_counter() - t0
        ok = bool(solved) and ss.haveExactSolutionPath()
        out.append((ok, t, ss.getSolutionPath().length() if ok else None))
    return out


def row(name, planner, runs):
    ok = [r for r in runs if r[0]]
    t = statistics.median(r[1] for r in runs)
    length = statistics.median(r[2] for r in ok) if ok else float("nan")
    return {"library": name, "planner": planner, "success": len(ok), "runs": len(runs),
            "median_time_ms": 1e3 * t, "median_length_m": length}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--timeout-s", type=float, default=10.0)
    ap.add_argument("--forkbench", default=os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "forkbench"))
    a = ap.parse_args()
    ensure_ompl()
    import ompl.util as ou
    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    tmp = tempfile.mkdtemp(prefix="ompl-compare-")
    subprocess.run([a.forkbench, "map", os.path.join(ROOT, "worlds", "warehouse.toml"),
                    "--margin-m", "0", "--inflate-m", str(INFLATE_M), "--out", tmp],
                   check=True, capture_output=True)
    yaml_path = os.path.join(tmp, "warehouse.yaml")
    rows = []
    for planner in ["prm", "rrt-connect"]:
        fb = row("forkbench", planner, forkbench_runs(a.forkbench, yaml_path, planner, a.runs))
        om = row("OMPL", planner, ompl_runs(yaml_path, planner, a.runs, a.timeout_s))
        om["time_ratio"] = om["median_time_ms"] / fb["median_time_ms"]
        rows += [fb, om]
    print(f"warehouse map, 5 cm cells inflated by {INFLATE_M} m; {START} → {GOAL}; {a.runs} runs each\n")
    print("| library | planner | success | median time to first solution | median length | OMPL / forkbench time |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        ratio = f"{r['time_ratio']:.0f}×" if "time_ratio" in r else ""
        print(f"| {r['library']} | {r['planner']} | {r['success']}/{r['runs']} | "
              f"{r['median_time_ms']:.2f} ms | {r['median_length_m']:.1f} m | {ratio} |")
    json.dump(rows, open(os.path.join(tmp, "ompl_compare.json"), "w"), indent=1)


if __name__ == "__main__":
    main()
