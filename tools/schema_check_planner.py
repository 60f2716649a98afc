#!/usr/bin/env python3
"""An external planner that checks the protocol's JSON Schemas against real traffic.

It validates every line forkbench sends against docs/schemas/planner-request.schema.json
and every answer of the example quintic planner against planner-response.schema.json,
and exits with a message on the first violation (the trial then fails as plan_failed,
which `.ci/run` sees). Needs `pip install jsonschema`. Run by tools/schema-check.toml.
"""
import sys

from schema_check import ROOT, serve

sys.path.insert(0, str(ROOT / "examples" / "planners"))
import quintic  # noqa: E402


def answer(msg):
    if not msg["obstacles"]:
        sys.stderr.write("schema check: expected the rack bay's obstacles in the request\n")
        sys.exit(1)
    try:
        return {"type": "path", "id": msg["id"], "samples": quintic.plan(msg), "cost": 0.0}
    except ValueError as e:
        return {"type": "error", "id": msg["id"], "message": str(e)}


serve("planner", answer)
