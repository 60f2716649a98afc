#!/usr/bin/env python3
"""Exits 1 unless two batch directories hold the same trials and summary (wall times aside)."""
import json
import sys


def records(d):
    out = []
    for line in open(f"{d}/trials.jsonl"):
        r = json.loads(line)
        r.pop("wall_time_ms", None)
        for leg in r.get("legs", []):
            leg.pop("planning_time_s", None)
        out.append(r)
    return sorted(out, key=lambda r: (r["scenario"], r["case"], r["planner"], r.get("tracker", ""), bool(r.get("replan")), r["trial"]))


def summary(d):
    s = json.load(open(f"{d}/summary.json"))
    s.pop("provenance", None)
    for row in s["rows"]:
        row.pop("wall_time_total_s", None)
    return s


a, b = sys.argv[1], sys.argv[2]
ra, rb = records(a), records(b)
if ra != rb:
    diff = sum(1 for x, y in zip(ra, rb) if x != y) + abs(len(ra) - len(rb))
    sys.exit(f"{a} and {b}: {len(ra)} vs {len(rb)} trials, {diff} differ")
if summary(a) != summary(b):
    sys.exit(f"{a} and {b}: summaries differ")
print(f"{b} equals {a}: {len(ra)} trials, summary identical (wall times aside)")
