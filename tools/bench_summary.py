#!/usr/bin/env python3
"""Median and max of criterion's per-benchmark median times, per group.

Usage: python3 tools/bench_summary.py TARGET_DIR/criterion GROUP [GROUP ...]
(e.g. after `cargo bench -p forkbench-plan --bench planners`: groups spiral, spiral-random).
"""

import json
import statistics
import sys
from pathlib import Path


def main():
    root = Path(sys.argv[1])
    for group in sys.argv[2:]:
        times = {}
        for est in sorted((root / group).glob("**/new/estimates.json")):
            name = str(est.parent.parent.relative_to(root / group))
            times[name] = json.loads(est.read_text())["median"]["point_estimate"] / 1e3
        if not times:
            print(f"{group}: no results under {root / group}")
            continue
        worst = max(times, key=times.get)
        print(
            f"{group}: {len(times)} benchmarks, median of medians {statistics.median(times.values()):.1f} µs, "
            f"max {times[worst]:.1f} µs ({worst})"
        )


if __name__ == "__main__":
    main()
