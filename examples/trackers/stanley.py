#!/usr/bin/env python3
"""A forkbench external tracker in plain Python: Stanley's steering law at the truck's fixed axle.

Speaks forkbench's tracker protocol (docs/external-tracker.md): one JSON object per line
on stdin and stdout. A `reset` brings the fork-root path to follow; each `tick` brings the
measured fork-root pose, speed and steering, and gets a command back.

The forklift steers its rear wheel; the front (drive) axle is the point that moves along
its own heading, so the controller works there, on the path shifted back by the fork
root's offset (as forkbench's pure pursuit does), with that path's own heading and
curvature. Stanley's law (Thrun et al. 2006) picks
the heading to hold: the path's, turned toward the path by atan(k e / (v + v0)) for a
cross-track error e; the curvature command is the path's plus a gain on the heading still
to turn, and the steering angle follows from the truck's wheelbase. The speed profile is
pure pursuit's: cruise, slower over the last metres, and a stop at the end.
No dependencies beyond the standard library. Forward paths only (a pick's).

`--shift-m D` makes it believe the truck D metres left of where it is: a calibration
error, for trying the regression gate (docs/gate.md) on a tracker that still enters.
"""
import json
import math
import sys

PROTOCOL, VERSION = "forkbench-tracker", 1
K_CROSS = 1.5         # Stanley gain on the cross-track error (1/s)
V_SOFT = 0.3          # softening speed (m/s): the law stays gentle when slow
K_HEADING = 2.0       # curvature per radian of heading still to turn (1/m)
CRUISE, APPROACH, APPROACH_M, DECEL = 0.8, 0.3, 2.0, 0.4
WINDOW = 300          # samples searched ahead of the last progress
SHIFT_M = 0.0         # believed offset to the left (m); set by --shift-m


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


class Stanley:
    def reset(self, msg):
        path, truck = msg["path"], msg["truck"]
        if path["reverse"]:
            raise ValueError("this example follows forward paths only")
        if len(path["samples"]) < 2:
            raise ValueError("the path needs at least two samples")
        d = truck["fork_root_ahead_of_front_axle_m"]
        # The front-axle path: each sample moved back along its heading by the root offset.
        # On a curve that path's own tangent is not the root path's heading, so its heading
        # and curvature come from its points.
        xy = [(x - d * math.cos(h), y - d * math.sin(h)) for _, x, y, h, _ in path["samples"]]
        xy = [p for i, p in enumerate(xy) if i == 0 or math.dist(p, xy[i - 1]) > 1e-6]
        if len(xy) < 2:
            raise ValueError("the path has no length")
        heads = [math.atan2(b[1] - a[1], b[0] - a[0]) for a, b in zip(xy, xy[1:])]
        heads.append(heads[-1])
        self.s = [0.0]
        for a, b in zip(xy, xy[1:]):
            self.s.append(self.s[-1] + math.dist(a, b))
        kappas = [wrap(heads[i + 1] - heads[i]) / max(self.s[i + 1] - self.s[i], 1e-9) for i in range(len(xy) - 1)]
        kappas.append(0.0)
        self.pts = [(p[0], p[1], h, k) for p, h, k in zip(xy, heads, kappas)]
        self.length = self.s[-1]
        self.d, self.truck, self.idx = d, truck, 0

    def closest(self, ax, ay):
        """The closest sample from the last progress on: a short window, widened while the
        best lies at its far edge (the truck moves about a sample a tick)."""
        pts, lo, width = self.pts, self.idx, 16
        while True:
            end = min(len(pts), lo + width)
            best = min(range(lo, end), key=lambda i: (pts[i][0] - ax) ** 2 + (pts[i][1] - ay) ** 2)
            if best < end - 1 or end == len(pts) or width >= WINDOW:
                return best
            lo, width = best, 2 * width

    def tick(self, msg):
        pose, v = msg["pose"], msg["speed_mps"]
        h = pose["heading_rad"]
        x, y = pose["x_m"] - SHIFT_M * math.sin(h), pose["y_m"] + SHIFT_M * math.cos(h)
        ax, ay = x - self.d * math.cos(h), y - self.d * math.sin(h)
        self.idx = self.closest(ax, ay)
        px, py, ph, pk = self.pts[self.idx]
        e = -math.sin(ph) * (ax - px) + math.cos(ph) * (ay - py)   # left of the path positive
        hold = ph - math.atan2(K_CROSS * e, abs(v) + V_SOFT)
        kappa = pk + K_HEADING * wrap(hold - h)
        truck = self.truck
        steer = max(-truck["max_steer_rad"], min(truck["max_steer_rad"], math.atan(truck["wheelbase_m"] * kappa)))
        gx, gy, gh, _ = self.pts[-1]
        along = math.cos(ph) * (ax - px) + math.sin(ph) * (ay - py)
        if self.length - self.s[self.idx] < 0.5:
            remaining = math.cos(gh) * (gx - ax) + math.sin(gh) * (gy - ay)
        else:
            remaining = self.length - self.s[self.idx] - along
        speed = min(CRUISE, truck["max_speed_mps"])
        if remaining < APPROACH_M:
            speed = min(speed, APPROACH)
        speed = min(speed, max(0.02, math.sqrt(2 * DECEL * max(remaining, 0.0))))
        done = remaining <= 0.002
        return {"speed_mps": 0.0 if done else speed, "steer_rad": steer, "done": done,
                "cross_track_m": e, "target": [px, py]}


def main():
    global SHIFT_M
    args = sys.argv[1:]
    if args[:1] == ["--shift-m"] and len(args) == 2:
        SHIFT_M = float(args[1])
    elif args:
        sys.exit("usage: stanley.py [--shift-m METRES]")
    tracker = Stanley()
    for line in sys.stdin:
        msg = json.loads(line)
        kind = msg["type"]
        if kind == "hello":
            reply = {"type": "hello", "protocol": PROTOCOL, "version": VERSION, "name": "stanley"}
        else:
            try:
                if kind == "reset":
                    tracker.reset(msg)
                    reply = {"type": "ok", "id": msg["id"]}
                else:
                    reply = {"type": "command", "id": msg["id"], **tracker.tick(msg)}
            except (ValueError, KeyError, IndexError) as e:
                reply = {"type": "error", "id": msg["id"], "message": f"{type(e).__name__}: {e}"}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
