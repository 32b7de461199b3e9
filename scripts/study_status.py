#!/usr/bin/env python3
"""Is a committed study current? What it ran, where, when, how often.

    scripts/study_status.py [--binary PATH] [--json] [STUDY_DIR ...]

For each study folder (default: every results/*/ with a cells.csv, or a
runs.csv of single runs, each row naming its run's folder in "dir"), from its
cells' run.json files and cells.csv:

- build: the git commits its cells were built from (and whether the tree was
  modified), date range, machine (CPU model, cores);
- repeats: the most runs any one cell setting has (cells.csv "repeat"; a
  reference run and a timed cell of the same solver are two settings);
- busy: cells that ran while other work used the machine (machine_busy = 1);
- stale solvers: a solver is stale when the definition its cells ran (outer
  method, inverse approximation and every option with its value in effect,
  solvers/solver_definition.h) hashes differently from what the current
  build makes of the same spec (`mpmbench list definitions --solver SPEC`).
  Old run.json files without solver_definition_hash get it recomputed from
  their outer_method, inverse_approximation and solver_options, exactly as the
  C code forms it.

A study is current when no solver of it is stale and every cell has its
run.json. Exit 0; 2 on bad arguments
or when the binary cannot say a spec's definition.
"""
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_BINARY = os.path.join(ROOT, "build", "mpmbench")


def fnv1a64(text):
    h = 0xcbf29ce484222325
    for b in text.encode():
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


def definition(run):
    """The definition text a run.json describes (solver_definition.c's form)."""
    if "solver_definition" in run:
        return run["solver_definition"]
    opts = run.get("solver_options", {})
    lines = ["outer=%s" % run["outer_method"], "inverse=%s" % run["inverse_approximation"]]
    lines += ["%s=%s" % (k, opts[k]) for k in sorted(opts, key=lambda k: k.encode())]
    return "\n".join(lines) + "\n"


def recorded_hash(run):
    return run.get("solver_definition_hash") or fnv1a64(definition(run))


def cell_spec(cell):
    """The spec a cell ran: its solver with its solver_opts folded in (a later
    option wins, as --solver-opt does after the spec's own)."""
    spec = cell["solver"]
    opts = [o for o in (cell.get("solver_opts") or "").split(";") if o]
    if not opts:
        return spec
    parts = spec.split(":")
    has_opts = len(parts) == 3 or (len(parts) == 2 and "=" in parts[1])
    return spec + ("," if has_opts else ":") + ",".join(opts)


def current_hashes(specs, binary):
    """{spec: hash} from the current build."""
    specs = sorted(set(specs))
    if not specs:
        return {}
    args = [binary, "list", "definitions"]
    for s in specs:
        args += ["--solver", s]
    out = subprocess.run(args, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError("%s list definitions: %s" % (binary, out.stderr.strip()))
    hashes = {}
    for line, spec in zip(out.stdout.splitlines(), specs):
        name, h = line.split()[:2]
        hashes[spec] = h
    return hashes


def read_cells(study):
    """cells.csv of a matrix study, else runs.csv of a study of single runs
    (a row per run, its folder in "dir"; a row whose "load" column is not
    "idle" ran beside a load on purpose, so its machine_busy is no fault)."""
    path = os.path.join(study, "cells.csv")
    if not os.path.isfile(path):
        path = os.path.join(study, "runs.csv")
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run_json_path(study, cell):
    if "dir" in cell:
        return os.path.join(study, cell["dir"], "run.json")
    return os.path.join(study, "cells", cell["id"], "run.json")


def unintended_busy(cell):
    return cell.get("machine_busy") == "1" and cell.get("load", "idle") == "idle"


def status(study, binary=DEFAULT_BINARY):
    cells = read_cells(study)
    commits, dirty, dates, cpus, cores = set(), False, [], set(), set()
    recorded = {}   # spec -> set of hashes its cells ran
    missing = 0
    for c in cells:
        path = run_json_path(study, c)
        try:
            with open(path) as f:
                run = json.load(f)
        except (OSError, ValueError):
            missing += 1
            continue
        recorded.setdefault(cell_spec(c) if "solver" in c else run["solver"], set()).add(recorded_hash(run))
        prov = run.get("provenance", {})
        build = prov.get("build", {})
        if build.get("git_commit"):
            commits.add(build["git_commit"][:7])
        dirty = dirty or bool(build.get("git_dirty"))
        if prov.get("start_time"):
            dates.append(prov["start_time"][:10])
        if prov.get("cpu_model"):
            cpus.add(prov["cpu_model"])
        if prov.get("cores_online"):
            cores.add(prov["cores_online"])
    now = current_hashes(recorded, binary)
    stale = sorted(s for s, hs in recorded.items() if hs != {now[s]})
    settings = {}
    measured = {"repeat", "s_per_frame", "machine_busy", "others_cpu_s", "dir"}
    for c in cells:
        key = tuple(v for k, v in sorted(c.items()) if k in
                    ("scene", "solver", "eps", "scale", "threads", "frames_asked", "first_timed_frame", "set",
                     "solver_opts", "role", "sample_frames")) if "id" in c else tuple(v for k, v in sorted(c.items()) if k not in measured)
        settings[key] = settings.get(key, 0) + 1
    return {
        "study": os.path.basename(os.path.normpath(study)),
        "cells": len(cells),
        "cells_without_run_json": missing,
        "builds": sorted(commits),
        "modified_tree": dirty,
        "dates": [min(dates), max(dates)] if dates else [],
        "machines": sorted(cpus),
        "cores": sorted(cores),
        "repeats": max(settings.values()) if settings else 0,
        "busy_cells": sum(unintended_busy(c) for c in cells),
        "busy_recorded": any("machine_busy" in c for c in cells),
        "stale_solvers": stale,
        # a cell whose run.json is missing cannot be judged: not current
        "current": not stale and not missing,
    }


def studies(args):
    if args:
        return args
    top = os.path.join(ROOT, "results")
    return sorted(os.path.join(top, d) for d in os.listdir(top)
                  if any(os.path.isfile(os.path.join(top, d, f)) for f in ("cells.csv", "runs.csv")))


def main(argv):
    binary, as_json, dirs = DEFAULT_BINARY, False, []
    i = 0
    while i < len(argv):
        if argv[i] == "--binary" and i + 1 < len(argv):
            binary = argv[i + 1]
            i += 2
        elif argv[i] == "--json":
            as_json = True
            i += 1
        elif argv[i].startswith("-"):
            print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
            return 2
        else:
            dirs.append(argv[i])
            i += 1
    try:
        out = [status(d, binary) for d in studies(dirs)]
    except (RuntimeError, OSError) as e:
        print("study_status.py: %s" % e, file=sys.stderr)
        return 2
    if as_json:
        json.dump(out, sys.stdout, indent=1)
        print()
        return 0
    for s in out:
        when = " to ".join(sorted(set(s["dates"]))) if s["dates"] else "?"
        busy = "%d busy" % s["busy_cells"] if s["busy_recorded"] else "load not recorded"
        state = "current" if s["current"] else (
            "stale for " + ", ".join(s["stale_solvers"]) if s["stale_solvers"] else
            "%d cells without run.json: cannot be shown current" % s["cells_without_run_json"])
        print("%-20s %4d cells, %s, build %s%s, %s, %s, repeats %d: %s" % (
            s["study"], s["cells"], when, "+".join(s["builds"]) or "?", " (modified)" if s["modified_tree"] else "",
            "/".join(s["machines"]) or "?", busy, s["repeats"], state))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
