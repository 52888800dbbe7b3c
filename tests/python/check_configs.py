#!/usr/bin/env python3
"""Validates configs with an independent JSON Schema implementation (Debian's python3-jsonschema).

Every shipped config and every valid test config must pass. Each invalid test config listed in
tests/configs/invalid/expected.json must fail if its entry says "schema": true (the schema itself
catches it) and must pass otherwise (only the tool's semantic checks catch it): that keeps the
schema and the tool's parser from drifting apart.
"""
import glob
import json
import os
import sys

import importlib.metadata

import jsonschema

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
schema = json.load(open(os.path.join(root, "schemas", "hairlut-config.schema.json")))
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)

failures = []
valid = sorted(glob.glob(os.path.join(root, "tables", "configs", "*.json")) +
               glob.glob(os.path.join(root, "tests", "configs", "valid", "*.json")))
for path in valid:
    errors = list(validator.iter_errors(json.load(open(path))))
    if errors:
        failures.append(f"{path}: expected valid, got: {errors[0].message}")
invalid_dir = os.path.join(root, "tests", "configs", "invalid")
expected = json.load(open(os.path.join(invalid_dir, "expected.json")))
for name, entry in sorted(expected.items()):
    errors = list(validator.iter_errors(json.load(open(os.path.join(invalid_dir, name + ".json")))))
    if entry["schema"] and not errors:
        failures.append(f"{name}: the schema accepts a config the tool must reject by schema")
    if not entry["schema"] and errors:
        failures.append(f"{name}: marked semantic-only, but the schema rejects it: {errors[0].message}")
for f in failures:
    print("FAIL", f)
print(f"{len(valid)} valid configs and {len(expected)} invalid configs checked with jsonschema {importlib.metadata.version('jsonschema')}")
sys.exit(1 if failures else 0)
