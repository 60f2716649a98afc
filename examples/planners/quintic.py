#!/usr/bin/env python3
"""A forkbench external planner in plain Python: a quintic polynomial pick path.

Speaks forkbench's planner protocol (docs/external-planner.md): one JSON object per
line on stdin and stdout. In the start frame the path is y(x), a quintic with
y(0) = 0, y'(0) = 0, y''(0) = kappa0 (the truck's current path curvature) and
y(X) = Y, y'(X) = tan(theta), y''(X) = 0 at the goal (X, Y, theta), so the curvature is
continuous from the truck's steering and zero where the forks go in straight.
No dependencies beyond the standard library.
"""
import json
import math
import sys

PROTOCOL, VERSION = "forkbench-planner", 1
SPACING_M = 0.01  # arc-length spacing of the samples


def solve3(a, b):
    """Solves the 3x3 system a x = b (Cramer's rule)."""
    def det(m):
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    d = det(a)
    out = []
    for col in range(3):
        m = [row[:] for row in a]
        for r in range(3):
            m[r][col] = b[r]
        out.append(det(m) / d)
    return out


def quintic(x_end, y_end, slope_end, kappa0):
    """Coefficients c0..c5 of y(x) for the six end conditions."""
    c0, c1, c2 = 0.0, 0.0, kappa0 / 2.0
    X = x_end
    # Remaining c3, c4, c5 from y(X), y'(X), y''(X).
    a = [[X**3, X**4, X**5], [3 * X**2, 4 * X**3, 5 * X**4], [6 * X, 12 * X**2, 20 * X**3]]
    b = [y_end - (c0 + c1 * X + c2 * X**2), slope_end - (c1 + 2 * c2 * X), 0.0 - 2 * c2]
    return [c0, c1, c2] + solve3(a, b)


def plan(req):
    s0, g = req["start"], req["goal"]
    h0 = s0["heading_rad"]
    dx, dy = g["x_m"] - s0["x_m"], g["y_m"] - s0["y_m"]
    c, s = math.cos(h0), math.sin(h0)
    X, Y = c * dx + s * dy, -s * dx + c * dy
    theta = math.atan2(math.sin(g["heading_rad"] - h0), math.cos(g["heading_rad"] - h0))
    if X <= 0.1 or abs(theta) >= math.radians(80):
        raise ValueError("the goal must lie ahead and within 80 degrees of the start heading")
    k = quintic(X, Y, math.tan(theta), req["start_curvature_per_m"])
    y = lambda x: sum(k[i] * x**i for i in range(6))
    d1 = lambda x: sum(i * k[i] * x ** (i - 1) for i in range(1, 6))
    d2 = lambda x: sum(i * (i - 1) * k[i] * x ** (i - 2) for i in range(2, 6))
    n = max(2, int(X / (SPACING_M / 4.0)))  # fine in x, thinned by arc length below
    samples, s_m, last_x, last_y = [], 0.0, 0.0, 0.0
    limit = req["truck"]["max_curvature_per_m"]
    for i in range(n + 1):
        x = X * i / n
        yx = y(x)
        s_m += math.hypot(x - last_x, yx - last_y)
        last_x, last_y = x, yx
        if samples and i < n and s_m - samples[-1][0] < SPACING_M:
            continue
        kappa = d2(x) / (1.0 + d1(x) ** 2) ** 1.5
        if abs(kappa) > limit:
            raise ValueError(f"needs |kappa| {abs(kappa):.3f} 1/m > kappa_max {limit:.3f} 1/m")
        heading = h0 + math.atan(d1(x))
        samples.append([s_m, s0["x_m"] + c * x - s * yx, s0["y_m"] + s * x + c * yx, heading, kappa])
    # Pin the ends exactly (the polynomial meets them up to rounding).
    samples[-1][1:4] = [g["x_m"], g["y_m"], h0 + theta]
    return samples


def main():
    for line in sys.stdin:
        msg = json.loads(line)
        if msg["type"] == "hello":
            reply = {"type": "hello", "protocol": PROTOCOL, "version": VERSION, "name": "quintic"}
        else:
            try:
                samples = plan(msg)
                reply = {"type": "path", "id": msg["id"], "samples": samples,
                         "info": {"coefficients": "quintic y(x) in the start frame"}}
            except ValueError as e:
                reply = {"type": "error", "id": msg["id"], "message": str(e)}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
