#!/usr/bin/env python3
"""An external detector that checks the detector protocol's JSON Schemas against real traffic.

It validates every line forkbench sends against docs/schemas/detector-request.schema.json
and every answer of the example RANSAC detector against detector-response.schema.json,
and exits with a message on the first violation (the trial then ends as an error, which
`.ci/run` sees). Needs `pip install jsonschema numpy`. Run by tools/schema-check-detector.toml.
"""
import json
import pathlib
import sys

import jsonschema

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples" / "detectors"))
import ransac  # noqa: E402

schemas = {
    name: json.loads((ROOT / "docs" / "schemas" / f"detector-{name}.schema.json").read_text())
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
        reply = {"type": "hello", "protocol": "forkbench-detector", "version": 1, "name": "schema-check"}
    else:
        reply = ransac.detect(msg)
    check("response", reply)
    print(json.dumps(reply), flush=True)
