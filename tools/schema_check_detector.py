#!/usr/bin/env python3
"""An external detector that checks the detector protocol's JSON Schemas against real traffic.

It validates every line forkbench sends against docs/schemas/detector-request.schema.json
and every answer of the example RANSAC detector against detector-response.schema.json,
and exits with a message on the first violation (the trial then ends as an error, which
`.ci/run` sees). Needs `pip install jsonschema`. Run by tools/schema-check-detector.toml.
"""
import sys

from schema_check import ROOT, serve

sys.path.insert(0, str(ROOT / "examples" / "detectors"))
import ransac  # noqa: E402

serve("detector", ransac.detect)
