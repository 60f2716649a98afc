#!/usr/bin/env python3
"""Validates JUnit XML files against docs/schemas/junit-10.xsd (the Jenkins/Surefire schema
pytest validates against); prints each file's tests and failures. Needs `pip install xmlschema`.
Usage: tools/validate_junit.py FILE.xml ... [--passing | --failing] (all cases pass, or some fail)"""
import pathlib
import sys

import xmlschema

schema = xmlschema.XMLSchema(str(pathlib.Path(__file__).resolve().parent.parent / "docs" / "schemas" / "junit-10.xsd"))
args = sys.argv[1:]
expect = None
for flag in ("--passing", "--failing"):
    if flag in args:
        expect = flag
        args.remove(flag)
for f in args:
    schema.validate(f)
    root = schema.to_dict(f)
    failures = int(root["@failures"])
    print(f"{f}: valid JUnit, {root['@tests']} tests, {failures} failures")
    if (expect == "--passing" and failures != 0) or (expect == "--failing" and failures == 0):
        sys.exit(f"{f}: expected {expect[2:]} cases, found {failures} failures")
