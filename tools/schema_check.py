"""The loop both schema-checking external components run: every line forkbench sends is
validated against docs/schemas/<protocol>-request.schema.json, every answer against
<protocol>-response.schema.json, and the first violation exits with a message (that trial
then fails, which `.ci/run` sees). Needs `pip install jsonschema`.
"""
import json
import pathlib
import sys

import jsonschema

ROOT = pathlib.Path(__file__).resolve().parent.parent


def serve(protocol, answer):
    """Answers hellos as `forkbench-<protocol>` version 1 and every other request with
    `answer(request)`, checking both directions against the protocol's schemas."""
    schemas = {
        name: json.loads((ROOT / "docs" / "schemas" / f"{protocol}-{name}.schema.json").read_text())
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
            reply = {"type": "hello", "protocol": f"forkbench-{protocol}", "version": 1, "name": "schema-check"}
        else:
            reply = answer(msg)
        check("response", reply)
        print(json.dumps(reply), flush=True)
