#!/usr/bin/env python3
"""Validates experiment-matrix files against docs/matrix.schema.json.

    python3 scripts/check_matrices.py [FILE.json ...]

Without arguments: every experiments/matrices/*.json. Prints one line per
file that fails (file, JSON path, message) and exits 1; exit 0 when all are
valid. Needs python3-jsonschema (scripts/test.sh installs it)."""
import glob
import json
import os
import sys

try:
    import jsonschema
except ImportError:
    sys.exit("check_matrices: python3-jsonschema is missing (apt-get install python3-jsonschema, "
             "or run scripts/test.sh, which installs it)")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_schema():
    with open(os.path.join(ROOT, "docs", "matrix.schema.json")) as f:
        schema = json.load(f)
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


def errors_of(validator, path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        return ["not readable JSON: %s" % e]
    out = []
    for e in sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path)):
        where = ".".join(str(p) for p in e.absolute_path) or "(top level)"
        out.append("%s: %s" % (where, e.message))
    return out


def main(argv):
    files = argv or sorted(glob.glob(os.path.join(ROOT, "experiments", "matrices", "*.json")))
    if not files:
        sys.exit("check_matrices: no matrix files")
    validator = load_schema()
    bad = 0
    for path in files:
        errs = errors_of(validator, path)
        for e in errs:
            print("%s: %s" % (os.path.relpath(path), e))
        bad += bool(errs)
    print("check_matrices: %d of %d files valid" % (len(files) - bad, len(files)), file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
