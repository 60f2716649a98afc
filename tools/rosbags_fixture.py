#!/usr/bin/env python3
"""Writes a ROS 2 bag with an independent writer (rosbags, MCAP storage) of TiM561 scans as a real driver publishes them, and the labels to score a detector on it.

The ranges come from `forkbench scan` (the field test's world, noise on) at 2 to 8 m and
-30 to 30 degrees of view; the bag has them in the scanner's own frame `laser`, no return
as NaN in some scans and +inf in others (drivers differ), the pallet out of view in some
(truck turned away), and a clutter post of two 0.1 m legs in front of the pallet in some.
The labels give the true face in the `laser` frame.

usage: rosbags_fixture.py FORKBENCH OUT_DIR
  writes OUT_DIR/bag/ (metadata.yaml and bag_0.mcap) and OUT_DIR/labels.json
"""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

FACE = (1.832533, 14.917769, math.radians(102.802))
RANGE_MIN, RANGE_MAX = 0.05, 10.0


def poses():
    """(fork root x, y, heading_deg, pallet in view) for each scan."""
    out = []
    fx, fy, fh = FACE
    for d in (2.5, 4.0, 6.7, 8.0):
        for a in (-30.0, 0.0, 30.0):
            b = fh + math.radians(a)
            x, y = fx - d * math.cos(b), fy - d * math.sin(b)
            out.append((x, y, math.degrees(b), True))
    # Turned away: the pallet behind the scanner's 270 degrees.
    for d in (3.0, 6.0):
        x, y = fx - d * math.cos(fh), fy - d * math.sin(fh)
        out.append((x, y, math.degrees(fh) + 180.0, False))
    return out


def to_local(sensor, p):
    dx, dy = p[0] - sensor[0], p[1] - sensor[1]
    c, s = math.cos(sensor[2]), math.sin(sensor[2])
    return (c * dx + s * dy, -s * dx + c * dy, p[2] - sensor[2])


def legs(angles, ranges, sensor, centre):
    """Occludes `ranges` with two 0.1 m legs (circles) 0.2 m apart at `centre` (map)."""
    for off in (-0.1, 0.1):
        lx, ly = to_local(sensor, (centre[0] + off, centre[1], 0.0))[:2]
        dist = math.hypot(lx, ly)
        for i, a in enumerate(angles):
            # Distance along the beam to the circle of radius 0.05 m.
            t = lx * math.cos(a) + ly * math.sin(a)
            miss = (lx - t * math.cos(a)) ** 2 + (ly - t * math.sin(a)) ** 2
            if t > 0 and miss <= 0.05**2 and dist < 9.0:
                r = t - math.sqrt(0.05**2 - miss)
                if not math.isfinite(ranges[i]) or r < ranges[i]:
                    ranges[i] = r


def scan(forkbench, x, y, h, seed):
    out = subprocess.run(
        [forkbench, "scan", "scenarios/field-test.toml", "--at", f"{x},{y},{h}",
         "--seed", str(seed), "--json"],
        check=True, capture_output=True, text=True,
    )
    return json.loads(out.stdout)


def main() -> None:
    forkbench, out_dir = sys.argv[1], Path(sys.argv[2])
    store = get_typestore(Stores.ROS2_HUMBLE)
    LaserScan = store.types["sensor_msgs/msg/LaserScan"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    bag = out_dir / "bag"
    if bag.exists():
        shutil.rmtree(bag)
    out_dir.mkdir(parents=True, exist_ok=True)
    labels = []
    with Writer(bag, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/scan", LaserScan.__msgtype__, typestore=store)
        for i, (x, y, h, present) in enumerate(poses()):
            r = scan(forkbench, x, y, h, seed=100 + i)
            angles = [b["angle_rad"] for b in r["beams"]]
            none = math.nan if i % 2 == 0 else math.inf
            ranges = [none if b["range_m"] is None else b["range_m"] for b in r["beams"]]
            sp = r["sensor_pose"]
            sensor = (sp["x_m"], sp["y_m"], sp["heading_rad"])
            t = r["truth"]
            face = (t["x_m"], t["y_m"], t["heading_rad"])
            if present and i % 3 == 1:
                # A person's legs 1.2 m before the face, off its centre line.
                c, s = math.cos(face[2]), math.sin(face[2])
                legs(angles, ranges, sensor, (face[0] - 1.2 * c - 0.8 * s, face[1] - 1.2 * s + 0.8 * c))
            stamp = Time(sec=1_700_000_000 + i, nanosec=0)
            msg = LaserScan(
                header=Header(stamp=stamp, frame_id="laser"),
                angle_min=angles[0], angle_max=angles[-1],
                angle_increment=(angles[-1] - angles[0]) / (len(angles) - 1),
                time_increment=0.0, scan_time=1.0 / 15.0,
                range_min=RANGE_MIN, range_max=RANGE_MAX,
                ranges=np.array(ranges, dtype=np.float32),
                intensities=np.array([], dtype=np.float32),
            )
            w.write(conn, stamp.sec * 10**9, store.serialize_cdr(msg, LaserScan.__msgtype__))
            label = {"index": i, "present": present}
            if present:
                lx, ly, lh = to_local(sensor, face)
                label["face"] = {"x_m": lx, "y_m": ly, "heading_deg": math.degrees(lh)}
            labels.append(label)
    (out_dir / "labels.json").write_text(json.dumps({"scans": labels}, indent=1) + "\n")
    print(f"wrote {bag} ({len(labels)} scans) and {out_dir / 'labels.json'}")


if __name__ == "__main__":
    main()
