#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Drafts a JSON schema (draft 2020-12) from example documents of one kind, for docs/schemas/.

    python3 scripts/schema_draft.py NAME/VERSION "TITLE" EXAMPLE.json... > docs/schemas/NAME.schema.json

Objects list every key seen (required: the keys of every example), arrays the union of their
elements, numbers are "number" (an integral double prints as an integer), a value seen as null is
nullable. The draft is a starting point: a maintainer reads it, adds the descriptions and units, and
commits it; tests/docs/check_schemas.py then validates every output of the tool against it.
"""
import json
import sys


def kind(value):
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    return "object"


def merge(values):
    """The schema of every value in `values` (examples of one field)."""
    kinds = sorted({kind(v) for v in values})
    schemas = []
    for k in kinds:
        of_kind = [v for v in values if kind(v) == k]
        if k == "object":
            keys = []
            for v in of_kind:
                keys += [key for key in v if key not in keys]
            schemas.append({
                "type": "object",
                "required": [key for key in keys if all(key in v for v in of_kind)],
                "additionalProperties": False,
                "properties": {key: merge([v[key] for v in of_kind if key in v]) for key in keys},
            })
        elif k == "array":
            items = [e for v in of_kind for e in v]
            schemas.append({"type": "array", "items": merge(items)} if items else {"type": "array"})
        else:
            schemas.append({"type": k})
    if len(schemas) == 1:
        return schemas[0]
    if all(set(s) == {"type"} for s in schemas):
        return {"type": [s["type"] for s in schemas]}
    return {"anyOf": schemas}


def main():
    name, title, paths = sys.argv[1], sys.argv[2], sys.argv[3:]
    docs = [json.load(open(p)) for p in paths]
    schema = {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": name, "title": title}
    schema.update(merge(docs))
    schema["properties"]["schema"] = {"const": name}
    json.dump(schema, sys.stdout, indent=2)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
