#!/usr/bin/env python3
"""An external planner that checks the protocol's JSON Schemas against real traffic.

It validates every line forkbench sends against docs/schemas/planner-request.schema.json
and every answer of the example quintic planner against planner-response.schema.json,
and exits with a message on the first violation (the trial then fails as plan_failed,
which `.ci/run` sees). Needs `pip install jsonschema`. Run by tools/schema-check.toml.
"""
import json
import pathlib
import sys

import jsonschema

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples" / "planners"))
import quintic  # noqa: E402

schemas = {
    name: json.loads((ROOT / "docs" / "schemas" / f"planner-{name}.schema.json").read_text())
    for name in ("request", "response")
}
for s in schemas.values():
    jsonschema.Draft202012Validator.check_schema(s)


def check(kind, msg):
    try:
        jsonschema.validate(msg, schemas[kind])
    except jsonschema.ValidationError as e:
        sys.stderr.write(f"schema check: {kind} violates its schema: {e.message}\n{json.dumps(msg)[:500]}\n")
        sys.exit(1)


for line in sys.stdin:
    msg = json.loads(line)
    check("request", msg)
    if msg["type"] == "hello":
        reply = {"type": "hello", "protocol": "forkbench-planner", "version": 1, "name": "schema-check"}
    else:
        if not msg["obstacles"]:
            sys.stderr.write("schema check: expected the rack bay's obstacles in the request\n")
            sys.exit(1)
        try:
            reply = {"type": "path", "id": msg["id"], "samples": quintic.plan(msg), "cost": 0.0}
        except ValueError as e:
            reply = {"type": "error", "id": msg["id"], "message": str(e)}
    check("response", reply)
    print(json.dumps(reply), flush=True)
