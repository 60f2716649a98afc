#!/usr/bin/env python3
"""An external tracker that checks the tracker protocol's JSON Schemas against real traffic.

It validates every line forkbench sends against docs/schemas/tracker-request.schema.json
and every answer of the example Stanley tracker against tracker-response.schema.json, and
exits with a message on the first violation (the trial then ends as an error, which
`.ci/run` sees). Needs `pip install jsonschema`. Run by tools/schema-check-tracker.toml.
"""
import sys

from schema_check import ROOT, serve

sys.path.insert(0, str(ROOT / "examples" / "trackers"))
import stanley  # noqa: E402

tracker = stanley.Stanley()


def answer(msg):
    if msg["type"] == "reset":
        tracker.reset(msg)
        return {"type": "ok", "id": msg["id"]}
    return {"type": "command", "id": msg["id"], **tracker.tick(msg)}


serve("tracker", answer)
