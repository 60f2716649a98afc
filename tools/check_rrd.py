#!/usr/bin/env python3
"""Checks an .rrd with rerun's own CLI (`rerun rrd verify`, then `rerun rrd print -vvv`): the
map, plot, verdict and event entities are there, the recording is named after the trial, and
the verdict text is the one the trial printed.

usage: check_rrd.py FILE.rrd TRIAL.json [--mission]

With --mission, a mission's navigation layer too: the blocked cells, the roadmap and each
leg's route.
"""
import json
import subprocess
import sys

ENTITIES = [
    "/map", "/map/initial", "/map/truck", "/map/plan/0", "/map/world/pallet",
    "/map/track/trajectory", "/map/track/now", "/map/sensors/nav350_fix",
    "/plots/lateral_error", "/plots/heading_error", "/plots/steering", "/verdict", "/events",
]


def main() -> None:
    rrd, trial_json = sys.argv[1], sys.argv[2]
    out = json.load(open(trial_json))
    entities = list(ENTITIES)
    if "--mission" in sys.argv[3:]:
        entities += ["/map/nav/occupied", "/map/nav/roadmap"]
        entities += [f"/map/nav/route/{i}" for i in range(len(out["legs"]))]
        entities += [f"/map/nav/route/{i}/reverse" for i, leg in enumerate(out["legs"])
                     if leg["reverse_length_m"] > 0]
        # Localised on reflectors: they, each fix's rays and its quality.
        entities += ["/map/nav350/reflectors", "/map/nav350/rays",
                     "/signals/nav350/reflectors_used", "/signals/localisation/fix_sigma_m"]
    subprocess.run(["rerun", "rrd", "verify", rrd], check=True)
    printed = subprocess.run(
        ["rerun", "rrd", "print", "-vvv", rrd], check=True, capture_output=True, text=True
    ).stdout
    missing = [e for e in entities if f"entity_path: {e} " not in printed]
    assert not missing, f"{rrd}: entities missing: {missing}"
    name = f"{out['scenario']} / {out['case']} / {out['planner']} / {out['tracker']} / seed {out['seed']}"
    assert name in printed, f"{rrd}: no recording named {name!r}"
    verdict = "SUCCESS" if out["success"] else f"FAILED: {out['failure']}"
    assert f"#### ✅ {verdict}" in printed or f"#### ❌ {verdict}" in printed, (
        f"{rrd}: no verdict {verdict!r}"
    )
    print(f"rrd ok: {len(entities)} entities, named {name!r}, verdict {verdict}")


if __name__ == "__main__":
    main()
