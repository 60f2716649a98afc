#!/usr/bin/env python3
"""A pallet detector for forkbench in Python: RANSAC line fit on the scan points near
where the pallet should be, stringer faces clustered along that line, face centre chosen
to match the pallet's stringer spacing. Standard library only, so it runs wherever
python3 does.

Protocol (docs/external-detector.md): JSON lines on stdin/stdout. First line each way is a
hello; then one answer per "detect" request: {"type": "pallet", "id", "face": pose} or
{"type": "none", "id"}. Anything else on stdout breaks the protocol: log to stderr.

Determinism: the RANSAC draws come from a generator seeded afresh for every request, so
the answer is a function of the request alone (whichever process or thread served it).
"""
import json
import math
import random
import sys

PROTOCOL, VERSION = "forkbench-detector", 1
ROI_M = 1.0          # points further than this from the prior face are not this pallet
INLIER_M = 0.025     # a point this close to the line lies on the face
ITERATIONS = 200
GAP_M = 0.08         # points further apart than this along the line: different stringers
SPACING_TOL_M = 0.08


def points_of(scan):
    """The scan's returns as map points, a list of (x, y)."""
    p = scan["pose"]
    out = []
    for i, r in enumerate(scan["ranges_m"]):
        if r is None or not math.isfinite(r):
            continue
        a = p["heading_rad"] + scan["angle_min_rad"] + scan["angle_step_rad"] * i
        out.append((p["x_m"] + r * math.cos(a), p["y_m"] + r * math.sin(a)))
    return out


def principal_axis(q):
    """Centroid and unit direction of largest spread of points q (a 2 x 2 eigenproblem)."""
    n = len(q)
    cx = sum(x for x, _ in q) / n
    cy = sum(y for _, y in q) / n
    sxx = sum((x - cx) ** 2 for x, _ in q)
    syy = sum((y - cy) ** 2 for _, y in q)
    sxy = sum((x - cx) * (y - cy) for x, y in q)
    angle = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    return (cx, cy), (math.cos(angle), math.sin(angle))


def ransac_line(pts, rng):
    """The line (point, unit direction) with the most inliers, refit by least squares."""
    best = None
    for _ in range(ITERATIONS):
        i, j = rng.sample(range(len(pts)), 2)
        dx, dy = pts[j][0] - pts[i][0], pts[j][1] - pts[i][1]
        n = math.hypot(dx, dy)
        if n < 0.05:
            continue
        nx, ny = -dy / n, dx / n
        xi, yi = pts[i]
        inliers = [p for p in pts if abs((p[0] - xi) * nx + (p[1] - yi) * ny) < INLIER_M]
        if best is None or len(inliers) > len(best):
            best = inliers
    if best is None or len(best) < 6:
        return None
    c, d = principal_axis(best)
    return c, d, best


def clusters(q, c, d):
    """Centres (positions along the line) of the runs of inlier points: stringer faces."""
    t = sorted((x - c[0]) * d[0] + (y - c[1]) * d[1] for x, y in q)
    groups, start = [], 0
    for k in range(1, len(t) + 1):
        if k == len(t) or t[k] - t[k - 1] > GAP_M:
            if k - start >= 3:
                groups.append(0.5 * (t[start] + t[k - 1]))
            start = k
    return groups


def face_centres(groups, spacing):
    """Where the face centre may be (along the line), from stringer pairs at the spacing."""
    out = []
    for a in range(len(groups)):
        for b in range(a + 1, len(groups)):
            gap = groups[b] - groups[a]
            if abs(gap - 2 * spacing) <= SPACING_TOL_M:
                out.append(0.5 * (groups[a] + groups[b]))
            elif abs(gap - spacing) <= SPACING_TOL_M:
                out.extend([groups[b], groups[a]])  # (left, centre) or (centre, right)
    return out


def detect(req):
    prior = req["prior"]
    spacing = req["pallet"]["stringer_offsets_m"][2]
    for k, scan in enumerate(req["scans"]):
        pts = points_of(scan)
        if prior is not None:
            pts = [p for p in pts if math.hypot(p[0] - prior["x_m"], p[1] - prior["y_m"]) < ROI_M]
        if len(pts) < 6:
            continue
        fit = ransac_line(pts, random.Random(0))
        if fit is None:
            continue
        c, d, q = fit
        centres = face_centres(clusters(q, c, d), spacing)
        if not centres:
            continue
        cands = [(c[0] + t * d[0], c[1] + t * d[1]) for t in centres]
        ref = (prior["x_m"], prior["y_m"]) if prior else c
        centre = min(cands, key=lambda p: math.hypot(p[0] - ref[0], p[1] - ref[1]))
        # Into the pallet: the face normal pointing away from the sensor.
        n = (-d[1], d[0])
        s = (scan["pose"]["x_m"], scan["pose"]["y_m"])
        if (centre[0] - s[0]) * n[0] + (centre[1] - s[1]) * n[1] < 0:
            n = (-n[0], -n[1])
        face = {"x_m": centre[0], "y_m": centre[1], "heading_rad": math.atan2(n[1], n[0])}
        return {"type": "pallet", "id": req["id"], "face": face, "sensor": k}
    return {"type": "none", "id": req["id"]}


def main():
    for line in sys.stdin:
        msg = json.loads(line)
        if msg.get("type") == "hello":
            reply = {"type": "hello", "protocol": PROTOCOL, "version": VERSION, "name": "ransac"}
        else:
            try:
                reply = detect(msg)
            except Exception as e:  # an answer, not a crash: the trial reports it
                reply = {"type": "error", "id": msg.get("id", 0), "message": repr(e)}
        print(json.dumps(reply), flush=True)


if __name__ == "__main__":
    main()
