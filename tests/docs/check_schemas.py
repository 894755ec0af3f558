#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Validates every kind of JSON document the tool writes against its schema in docs/schemas/.

    check_schemas.py <repo root> <path to hexatwist binary> [--examples DIR]

Runs the commands that write JSON (each kind in a few variants: a success, a refusal that still
prints JSON, another configuration), reads each document's "schema" field (NAME/VERSION), and
validates the document against docs/schemas/NAME.schema.json, whose $id must be that NAME/VERSION.
Every schema file must be met by at least one document, and every document must name a schema.
With --examples DIR the documents are also written there (for scripts/schema_draft.py).

Exit 0 when everything holds; 1 with one line per problem. Needs python3-jsonschema.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import jsonschema

def main() -> int:
    root, tool = Path(sys.argv[1]), sys.argv[2]
    examples = Path(sys.argv[sys.argv.index("--examples") + 1]) if "--examples" in sys.argv else None
    problems: list[str] = []
    documents: list[tuple[str, dict]] = []  # (where, document)

    with tempfile.TemporaryDirectory(prefix="hexatwist_schemas_") as scratch:
        work = Path(scratch)
        legs = str(root / "configs" / "seed-legs.yaml")

        def run(args: list[str], codes: tuple[int, ...] = (0,)) -> str:
            r = subprocess.run([tool, *args], cwd=work, capture_output=True, text=True, timeout=600)
            if r.returncode not in codes:
                problems.append(f"hexatwist {' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")
            return r.stdout

        def printed(args: list[str], codes: tuple[int, ...] = (0,)) -> None:
            out = run(args, codes)
            try:
                documents.append((f"hexatwist {' '.join(args)}", json.loads(out)))
            except json.JSONDecodeError as e:
                problems.append(f"hexatwist {' '.join(args)}: not one JSON document: {e}")

        def file(path: str) -> None:
            p = work / path
            if not p.exists():
                problems.append(f"{path}: not written")
                return
            documents.append((path, json.loads(p.read_text())))

        printed(["ik", "--json"])
        printed(["ik", "--config", legs, "--pose", "0.01,0,0.05,1,2,3", "--json"])
        printed(["ik", "--pose", "0,0,0.9,0,0,0", "--json"], (3,))
        home = json.loads(run(["ik", "--json"]))
        lengths = ",".join(repr(leg["command_compensated"]) for leg in home["legs"])
        printed(["fk", "--lengths", lengths, "--motor", "--json"])
        printed(["fk", "--lengths", "9,9,9,9,9,9", "--json"], (3,))
        printed(["config", "--json"])
        printed(["config", "--config", legs, "--json"])
        printed(["stations", "--count", "20", "--candidates", "200", "--out", "run.csv", "--json"])
        run(["synth", "--stations", "20", "--joint-errors-mm", "0.5", "--lead-error-pct", "2", "--out", "log.csv"])
        file("log.truth.json")
        run(["synth", "--stations", "20", "--joint-errors-mm", "0.5", "--stiffness-n-per-um", "200", "--play-um",
             "30", "--temperature-rise-k", "1", "--out", "warm.csv"])
        file("warm.truth.json")
        printed(["compare", str(root / "configs" / "seed.yaml"), "warm.real.yaml", "--stations", "10", "--json"])
        printed(["identify", "--stations", "20", "--points", "log.csv", "--out", "id.yaml", "--json"])
        printed(["identify", "--stations", "20", "--points", "warm.csv", "--effects", "none", "--json"], (0, 5))
        printed(["identify", "--stations", "20", "--points", "warm.csv", "--out", "warm.yaml", "--json"], (0, 5))
        printed(["ik", "--config", "warm.yaml", "--pose", "0.01,0,0.05,1,2,3", "--json"])  # with the legs' effects
        for command, out in (("study", "st"), ("simulate", "si"), ("dynamics", "dy")):
            args = ["--no-figures", "--no-csv", "--out", out]
            args += ["--tests", "Rz"] if command == "study" else ["--trajectory", "run.csv"]
            run([command, *args])
            file(f"{out}/summary.json")
            file(f"{out}/.hexatwist-run.json")
        # The study of a configuration with every leg effect: its leg_effects table.
        seed = (root / "configs" / "seed.yaml").read_text()
        (work / "effects.yaml").write_text(
            seed.replace("  angular_amplitude_deg: 30 ", "  angular_amplitude_deg: 5 ")
            + "\nleg_effects:\n  stiffness: 2.0e8\n  play: 50.0e-6\n  length_expansion: 11.5e-6\n")
        run(["study", "--config", "effects.yaml", "--tests", "Rz", "--temperature-rise-k", "1", "--no-figures",
             "--no-csv", "--out", "fx"])
        file("fx/summary.json")
        run(["synth", "--test", "Lz", "--out", "lz.csv"])
        run(["measure", "--test", "Lz", "--points", "lz.csv", "--no-figures", "--no-csv", "--out", "me"])
        file("me/summary.json")
        small = ["--workspace", "tests=off,random=5"]
        printed(["design", *small, "--cell", "0.1", "--out", "d.yaml", "--json"])
        printed(["tolerance", *small, "--platforms", "5", "--no-figures", "--no-csv", "--out", "to", "--json"])
        file("to/summary.json")
        # After a tracker calibration with more targets, comparing layouts of them.
        printed(["tolerance", *small, "--platforms", "3", "--calibration", "stations:20", "--points-per-station", "3",
                 "--targets-mm", "-600,0,0", "--target-layouts", "1", "--no-figures", "--no-csv", "--out", "tt",
                 "--json"])
        # A yaw of 80 deg is out of reach at zero tilt: its extremes are null.
        printed(["workspace", "--heights", "0", "--spacing", "0.1", "--yaws", "0,80", "--map-spacing", "0.2", "--cell",
                 "0.1", "--no-figures", "--no-csv", "--out", "ws", "--json"])
        file("ws/summary.json")
        # No map node inside the workspace at z = 0.9 m: the map's extremes are null.
        printed(["workspace", "--heights", "0", "--spacing", "0.1", "--yaws", "0", "--map-height", "0.9",
                 "--map-spacing", "0.2", "--cell", "0.1", "--no-figures", "--no-csv", "--out", "ws-empty-map", "--json"])

    met: set[str] = set()
    for k, (where, doc) in enumerate(documents):
        name = doc.get("schema") if isinstance(doc, dict) else None
        if not isinstance(name, str) or "/" not in name or not name.startswith("hexatwist."):
            problems.append(f"{where}: no \"schema\": \"hexatwist.NAME/VERSION\" field")
            continue
        if examples is not None:
            examples.mkdir(parents=True, exist_ok=True)
            (examples / f"{name.split('/')[0][len('hexatwist.'):]}.{k}.json").write_text(json.dumps(doc))
        path = root / "docs" / "schemas" / f"{name.split('/')[0][len('hexatwist.'):]}.schema.json"
        if not path.exists():
            problems.append(f"{where}: its schema {name} has no file {path.relative_to(root)}")
            continue
        schema = json.loads(path.read_text())
        if schema.get("$id") != name:
            problems.append(f"{path.relative_to(root)}: $id {schema.get('$id')} but the tool writes {name}")
            continue
        met.add(path.name)
        try:
            jsonschema.validate(doc, schema)
        except jsonschema.ValidationError as e:
            at = "/".join(str(p) for p in e.absolute_path)
            problems.append(f"{where}: not valid against {path.relative_to(root)} at /{at}: {e.message[:300]}")
    for schema_file in sorted((root / "docs" / "schemas").glob("*.schema.json")):
        if schema_file.name not in met:
            problems.append(f"docs/schemas/{schema_file.name}: no output of the tool was validated against it")
    for p in problems:
        print(p)
    print(f"{len(documents)} documents, {len(met)} schemas, {len(problems)} problems", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
