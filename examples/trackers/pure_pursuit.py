#!/usr/bin/env python3
"""forkbench's pure pursuit, rewritten in plain Python as an external tracker.

Speaks forkbench's tracker protocol (docs/external-tracker.md): one JSON object per line
on stdin and stdout. It follows the built-in `pure_pursuit` with its default settings
(crates/forkbench-track/src/pursuit.rs): the front axle pursues the fork-root path
shifted back by the root's offset, a fixed 0.7 m look-ahead, 0.8 m/s cruise, 0.3 m/s over
the last 2 m, and a stop profile that allows for how far the drive runs on after a zero
command. It is what a team's own reimplementation looks like, for gating one against the
built-in (docs/gate.md): faithful, but not the same code.

`--shift-m D` makes it believe the truck D metres left of where it is: a calibration
error, for trying the gate on a tracker whose picks still succeed.
No dependencies beyond the standard library.
"""
import json
import math
import sys

PROTOCOL, VERSION = "forkbench-tracker", 1
LOOKAHEAD_M, CRUISE, APPROACH, APPROACH_M, DECEL = 0.7, 0.8, 0.3, 2.0, 0.4
WINDOW = 400          # samples searched ahead of the last progress
SHIFT_M = 0.0         # believed offset to the left (m); set by --shift-m


def wrap(a):
    a = a % (2 * math.pi)
    return a - 2 * math.pi if a > math.pi else a


class PurePursuit:
    def reset(self, msg):
        path, truck = msg["path"], msg["truck"]
        self.reverse, self.truck = path["reverse"], truck
        self.d = truck["fork_root_ahead_of_front_axle_m"]
        self.pts = []
        for s, x, y, h, k in path["samples"]:
            x, y = x - self.d * math.cos(h), y - self.d * math.sin(h)
            if self.reverse:
                h = wrap(h + math.pi)
            self.pts.append((s, x, y, h, k))
        if not self.pts:
            raise ValueError("the path has no samples")
        self.length = self.pts[-1][0]
        self.goal_sin, self.goal_cos = math.sin(self.pts[-1][3]), math.cos(self.pts[-1][3])
        drive, control = truck.get("drive", {}), truck.get("control", {})
        self.run_on_s = (drive.get("dead_time_s", 0.0) + control.get("transport_delay_s", 0.0)
                         + (drive.get("time_constant_s") or 0.0))
        self.creep = drive.get("creep_speed_mps", 0.0)
        self.idx = 0

    def closest(self, x, y):
        best, best_d2 = self.idx, None
        for i in range(self.idx, min(self.idx + WINDOW, len(self.pts))):
            _, px, py, _, _ = self.pts[i]
            d2 = (px - x) ** 2 + (py - y) ** 2
            if best_d2 is None or d2 < best_d2:
                best, best_d2 = i, d2
        return best

    def lookahead(self, x, y, start):
        for i in range(start, len(self.pts)):
            _, px, py, _, _ = self.pts[i]
            if (px - x) ** 2 + (py - y) ** 2 >= LOOKAHEAD_M ** 2:
                return px, py
        # Past the end: a point on the goal heading's extension, at the look-ahead distance.
        _, lx, ly, _, _ = self.pts[-1]
        gs, gc = self.goal_sin, self.goal_cos
        along = gc * (x - lx) + gs * (y - ly)
        lat = -gs * (x - lx) + gc * (y - ly)
        ext = max(LOOKAHEAD_M, 0.05)
        t = along + math.sqrt(max(ext * ext - lat * lat, 0.0))
        return lx + gc * t, ly + gs * t

    def tick(self, msg):
        pose, v = msg["pose"], msg["speed_mps"]
        h = pose["heading_rad"]
        rx, ry = pose["x_m"] - SHIFT_M * math.sin(h), pose["y_m"] + SHIFT_M * math.cos(h)
        x, y = rx - self.d * math.cos(h), ry - self.d * math.sin(h)
        if self.reverse:
            h = wrap(h + math.pi)
        self.idx = best = self.closest(x, y)
        s, nx, ny, nh, _ = self.pts[best]
        sn, cn = math.sin(nh), math.cos(nh)
        cross = -sn * (x - nx) + cn * (y - ny)
        along = cn * (x - nx) + sn * (y - ny)
        _, lx, ly, _, _ = self.pts[-1]
        if self.length - s < 0.5:
            remaining = self.goal_cos * (lx - x) + self.goal_sin * (ly - y)
        else:
            remaining = self.length - s - along
        tx, ty = self.lookahead(x, y, best)
        dist = max(math.hypot(tx - x, ty - y), 1e-6)
        eta = wrap(math.atan2(ty - y, tx - x) - h)
        kappa = 2.0 * math.sin(eta) / dist
        if self.reverse:
            kappa = -kappa
        t = self.truck
        steer = max(-t["max_steer_rad"], min(t["max_steer_rad"], math.atan(t["wheelbase_m"] * kappa)))
        speed = min(CRUISE, t["max_speed_mps"])
        if remaining < APPROACH_M:
            speed = min(speed, APPROACH)
        d = remaining - abs(v) * self.run_on_s
        speed = min(speed, max(math.sqrt(2 * DECEL * max(d, 0.0)), 0.02, self.creep))
        done = remaining <= 0.002
        sign = -1.0 if self.reverse else 1.0
        return {"speed_mps": 0.0 if done else sign * speed, "steer_rad": steer, "done": done,
                "cross_track_m": cross, "target": [tx, ty]}


def main():
    global SHIFT_M
    args = sys.argv[1:]
    if args[:1] == ["--shift-m"] and len(args) == 2:
        SHIFT_M = float(args[1])
    elif args:
        sys.exit("usage: pure_pursuit.py [--shift-m METRES]")
    tracker = PurePursuit()
    for line in sys.stdin:
        msg = json.loads(line)
        kind = msg["type"]
        if kind == "hello":
            reply = {"type": "hello", "protocol": PROTOCOL, "version": VERSION, "name": "pure_pursuit.py"}
        else:
            try:
                if kind == "reset":
                    tracker.reset(msg)
                    reply = {"type": "ok", "id": msg["id"]}
                else:
                    reply = {"type": "command", "id": msg["id"], **tracker.tick(msg)}
            except (ValueError, KeyError, IndexError, TypeError) as e:
                reply = {"type": "error", "id": msg["id"], "message": f"{type(e).__name__}: {e}"}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
