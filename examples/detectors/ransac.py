#!/usr/bin/env python3
"""A pallet detector for forkbench in Python: RANSAC line fit on the scan points near
where the pallet should be, stringer faces clustered along that line, face centre chosen
to match the pallet's stringer spacing.

Protocol (docs/external-detector.md): JSON lines on stdin/stdout. First line each way is a
hello; then one answer per "detect" request: {"type": "pallet", "id", "face": pose} or
{"type": "none", "id"}. Anything else on stdout breaks the protocol: log to stderr.

Determinism: the RANSAC draws come from a generator seeded afresh for every request, so
the answer is a function of the request alone (whichever process or thread served it).
"""
import json
import math
import sys

import numpy as np

PROTOCOL, VERSION = "forkbench-detector", 1
ROI_M = 1.0          # points further than this from the prior face are not this pallet
INLIER_M = 0.025     # a point this close to the line lies on the face
ITERATIONS = 200
GAP_M = 0.08         # points further apart than this along the line: different stringers
SPACING_TOL_M = 0.08


def points_of(scan):
    """The scan's returns as map points (a numpy array of shape (n, 2))."""
    p = scan["pose"]
    r = np.array([np.nan if v is None else v for v in scan["ranges_m"]], dtype=float)
    a = p["heading_rad"] + scan["angle_min_rad"] + scan["angle_step_rad"] * np.arange(len(r))
    ok = np.isfinite(r)
    return np.stack([p["x_m"] + r[ok] * np.cos(a[ok]), p["y_m"] + r[ok] * np.sin(a[ok])], axis=1)


def ransac_line(pts, rng):
    """The line (point, unit direction) with the most inliers, refit by least squares."""
    best = None
    for _ in range(ITERATIONS):
        i, j = rng.choice(len(pts), size=2, replace=False)
        d = pts[j] - pts[i]
        n = np.linalg.norm(d)
        if n < 0.05:
            continue
        d = d / n
        dist = np.abs((pts - pts[i]) @ np.array([-d[1], d[0]]))
        inliers = dist < INLIER_M
        if best is None or inliers.sum() > best.sum():
            best = inliers
    if best is None or best.sum() < 6:
        return None
    q = pts[best]
    c = q.mean(axis=0)
    _, _, vt = np.linalg.svd(q - c)
    return c, vt[0], q


def clusters(q, c, d):
    """Centres (positions along the line) of the runs of inlier points: stringer faces."""
    t = np.sort((q - c) @ d)
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
        if prior is not None and len(pts):
            near = np.hypot(pts[:, 0] - prior["x_m"], pts[:, 1] - prior["y_m"]) < ROI_M
            pts = pts[near]
        if len(pts) < 6:
            continue
        fit = ransac_line(pts, np.random.default_rng(0))
        if fit is None:
            continue
        c, d, q = fit
        centres = face_centres(clusters(q, c, d), spacing)
        if not centres:
            continue
        cands = [c + t * d for t in centres]
        ref = np.array([prior["x_m"], prior["y_m"]]) if prior else c
        centre = min(cands, key=lambda p: np.hypot(*(p - ref)))
        # Into the pallet: the face normal pointing away from the sensor.
        n = np.array([-d[1], d[0]])
        s = np.array([scan["pose"]["x_m"], scan["pose"]["y_m"]])
        if (centre - s) @ n < 0:
            n = -n
        face = {"x_m": float(centre[0]), "y_m": float(centre[1]),
                "heading_rad": math.atan2(n[1], n[0])}
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
