#!/usr/bin/env python3
"""Checks a forkbench ROS 2 bag (`trial --ros2 DIR`, a rosbag2 directory) with two independent readers: rosbags opens the directory by its metadata.yaml as `ros2 bag play` does (its counts must match the messages) and deserialises the CDR with its built-in ROS 2 Humble definitions (not the bag's), and mcap-ros2-support decodes every message with the bag's own ros2msg schemas, so a schema and an encoding that agree with each other but not with ROS 2 fail.

usage: check_ros2.py BAG_DIR OUTCOME.json [--mission]
"""

import json
import math
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.reader import read_ros2_messages
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

# ackermann_msgs is not among Humble's core definitions: its published .msg files, as
# ros-drivers/ackermann_msgs has them (not the bag's copy).
ACKERMANN = {
    "ackermann_msgs/msg/AckermannDrive": "float32 steering_angle\nfloat32 steering_angle_velocity\n"
    "float32 speed\nfloat32 acceleration\nfloat32 jerk\n",
    "ackermann_msgs/msg/AckermannDriveStamped": "std_msgs/Header header\nAckermannDrive drive\n",
}


def main() -> None:
    bag_dir, outcome_file = Path(sys.argv[1]), sys.argv[2]
    mission = "--mission" in sys.argv[3:]
    outcome = json.load(open(outcome_file))
    # The directory as rosbag2 opens it: metadata.yaml names the MCAP and counts each
    # topic's messages, which must be the messages the MCAP holds.
    with Reader(bag_dir) as r:
        listed = {c.topic: c.msgcount for c in r.connections}
        found = {}
        for c, _, _ in r.messages():
            found[c.topic] = found.get(c.topic, 0) + 1
        assert {t: n for t, n in listed.items() if n} == found, (listed, found)
        assert r.message_count == sum(found.values())
    files = sorted(bag_dir.glob("*.mcap"))
    assert len(files) == 1 and sorted(p.name for p in bag_dir.iterdir()) == sorted(
        ["metadata.yaml", files[0].name]), list(bag_dir.iterdir())
    bag = str(files[0])
    with open(bag, "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        summary = reader.get_summary()
        assert header.profile == "ros2", header.profile
        for s in summary.schemas.values():
            assert s.encoding == "ros2msg", (s.name, s.encoding)
        for c in summary.channels.values():
            assert c.message_encoding == "cdr", (c.topic, c.message_encoding)
        types = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    # Every message decodes with the bag's own schemas.
    decoded = {}
    count = 0
    for m in read_ros2_messages(bag):
        decoded.setdefault(m.channel.topic, []).append(m.ros_msg)
        count += 1
    # And with ROS 2 Humble's own definitions.
    store = get_typestore(Stores.ROS2_HUMBLE)
    for name, text in ACKERMANN.items():
        store.register(get_types_from_msg(text, name))
    with open(bag, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages():
            store.deserialize_cdr(message.data, types[channel.topic])
    tf = decoded["/tf"]
    root = [t for m in tf for t in m.transforms if t.child_frame_id == "fork_root"]
    assert root and all(t.header.frame_id == "map" for t in root)
    q = root[-1].transform.rotation
    assert abs(q.x**2 + q.y**2 + q.z**2 + q.w**2 - 1) < 1e-9
    scans = [m for topic, ms in decoded.items() if topic.startswith("/scan/") for m in ms]
    assert scans, sorted(decoded)
    s = scans[0]
    assert s.header.frame_id.startswith("scanner_") and len(s.ranges) > 100
    assert all(s.range_min <= r <= s.range_max or math.isinf(r) for r in s.ranges)
    plan = decoded["/forkbench/plan"][0]
    assert len(plan.poses) > 10 and plan.header.frame_id == "map"
    last = json.loads(decoded["/forkbench/outcome"][-1].data)
    assert last["success"] == outcome["success"] and last["seed"] == outcome["seed"], last
    scene = decoded["/forkbench/scene"][0].markers
    locked = {m.ns for m in scene if m.frame_locked}
    assert {"truck", "pallet"} <= locked, locked
    assert all(m.header.frame_id in ("map", "fork_root", "pallet") for m in scene)
    assert decoded["/forkbench/fix"] and decoded["/forkbench/pallet_estimate"], sorted(decoded)
    for topic, ms in decoded.items():
        for m in ms if topic.startswith("/grid/") else []:
            assert len(m.data) == m.info.width * m.info.height > 0, topic
            assert all(0 <= v <= 100 for v in m.data), topic
    if mission:
        assert any(t.startswith("/grid/nav") for t in decoded), sorted(decoded)
        assert decoded["/markers"], sorted(decoded)
        assert any(m.ns == "obstacles" and m.type == 1 for m in scene), "no racks in the scene"
    # The actuators: a commanded and a measured drive message for every estimated pose.
    asked, got = decoded["/forkbench/actuators/command"], decoded["/forkbench/actuators/measured"]
    assert len(asked) == len(got) == len(decoded["/forkbench/pose"]), (len(asked), len(got))
    assert any(m.drive.steering_angle != 0 for m in got) and any(m.drive.speed > 0 for m in got)
    levels = {m.level for m in decoded["/rosout"]}
    assert levels <= {20, 30, 40}, levels
    print(f"ros2 bag directory ok: {count} messages on {len(decoded)} topics, {len(scans)} scans, "
          f"{len(root)} fork-root transforms, outcome {'success' if last['success'] else last['failure']}")


if __name__ == "__main__":
    main()
