#!/usr/bin/env python3
"""The floors of docs/design.md, checked on the sources' #include lines.

    scripts/check_includes.py [ROOT]

Every C file under core/, solvers/, adapters/ and experiments/ of ROOT (default:
the repository this script is in) belongs to one part, the part of its folder.
A part may include the headers of the parts listed for it in PARTS below and
the third-party headers listed for it, nothing else: a header of a higher
floor or of a sideways part is an error, so is a third-party header outside
its floor (the compiler finds jansson.h or mpi.h from anywhere). Adapters see
only their own headers among the adapters (adapters/NAME.h and the
headers of their parts adapters/NAME_*.h) and the shared modules (the MPI
start-up), and only the registry reads the
adapters' list. Modules (a .c with its .h) must not
include each other in a circle.

Every C file under tests/ names the floor it tests in a line of its own,
"/* floor: solvers */" (tests/CMakeLists.txt links it against that floor
only); its project #include lines may name only that floor and the ones below
it (TEST_FLOORS), a test helper header counting as the floor its own line
names. Prints one line per violation and exits 1 when there is one, 0 when
there is none, 2 on bad arguments.
"""
import fnmatch
import os
import re
import sys

# part: (folder, project parts it may include, third-party headers it may include)
# Lowest floor first. A folder's part is the longest folder that holds it.
PARTS = {
    "core": ("core", {"core"}, set()),
    "scene": ("core/scene", {"core", "scene"}, {"jansson.h"}),
    "solvers": ("solvers", {"core", "solvers"}, set()),
    "adapters": ("adapters", {"core", "solvers", "adapters"},
                 {"mpi.h", "HYPRE*.h", "_hypre*.h", "cholmod*.h", "ml_*.h", "Trilinos_*.h", "petsc*.h"}),
    "driver": ("experiments/driver", {"core", "scene", "solvers", "driver"}, set()),
    # the application, in layers: each uses the ones above it in this list
    "io": ("experiments/io", {"core", "io"}, set()),
    "accuracy": ("experiments/accuracy", {"core", "scene", "solvers", "driver", "io", "accuracy"}, {"jansson.h"}),
    "run": ("experiments/run", {"core", "scene", "solvers", "driver", "io", "accuracy", "run"}, {"jansson.h", "mpi.h"}),
    "cli": ("experiments/cli", {"core", "scene", "solvers", "driver", "io", "accuracy", "run", "cli"}, set()),
    "bench": ("experiments/bench", {"core", "scene", "solvers", "driver", "io", "run", "cli", "bench"}, set()),
    "render": ("experiments/render", {"core", "scene", "solvers", "driver", "io", "run", "cli", "render"}, {"png.h"}),
    "matrix": ("experiments/matrix", {"core", "scene", "solvers", "driver", "io", "accuracy", "run", "cli", "matrix"},
               {"jansson.h", "mpi.h"}),
    "dist": ("experiments/dist", {"core", "scene", "solvers", "driver", "io", "run", "cli", "dist"}, set()),
    "commands": ("experiments/commands", {"core", "scene", "solvers", "driver", "io", "accuracy", "run", "cli", "bench",
                                          "render", "matrix", "dist", "commands"}, set()),
}
# third-party headers: any <...> include matching one of these needs the part's permission
THIRD_PARTY = ["jansson.h", "png.h", "mpi.h", "HYPRE*.h", "_hypre*.h", "cholmod*.h", "ml_*.h", "Trilinos_*.h",
               "petsc*.h", "gsl/*"]
# generated at build time into the build folder (CMakeLists.txt), and the
# part whose target carries it
GENERATED = {"mpm_build_info.h": "run", "mpm_adapters_built.h": "adapters"}
# the registry is the one meeting point of the adapters and the rest: it alone
# reads their list (no file outside adapters/ includes an adapter's header)
MEETING_POINT = ("experiments/driver/registry.c", "adapters/adapter_list.h")
# modules under adapters/ that every adapter may use: they belong to no adapter
SHARED_ADAPTER_MODULES = {"adapters/mpi_startup"}
SOURCE_EXT = (".c", ".h", ".inc")
# a test's floor: the parts its #include lines may name (its floor and those below)
TEST_FLOORS = {
    "core": {"core"},
    "scene": {"core", "scene"},
    "solvers": {"core", "solvers"},
    "adapters": {"core", "solvers", "adapters"},
    "driver": {"core", "scene", "solvers", "adapters", "driver"},
    "app": set(PARTS),
}
# outside the floors' folders: the worked example of docs/solvers.md is an inverse approximation
EXTRA_PARTS = {"docs/examples": "solvers"}
FLOOR_LINE = re.compile(r"^/\* floor: ([a-z ]+) \*/")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def part_of(path):
    best = None
    for name, (folder, _, _) in PARTS.items():
        if path == folder or path.startswith(folder + "/"):
            if best is None or len(folder) > len(PARTS[best][0]):
                best = name
    return best


def sources(root):
    for top in ("core", "solvers", "adapters", "experiments"):
        for d, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if f.endswith(SOURCE_EXT):
                    yield os.path.relpath(os.path.join(d, f), root)


def module(path):
    return os.path.splitext(path)[0]


def adapter_of(path):
    """The adapter a file under adapters/ belongs to: NAME for adapters/NAME.c
    and its own parts adapters/NAME_*.c (and their headers)."""
    return os.path.basename(module(path)).split("_")[0]


def find_cycle(edges):
    """A list of modules forming a circle, or None."""
    state = {}

    def visit(m, stack):
        state[m] = 1
        stack.append(m)
        for n in sorted(edges.get(m, ())):
            if state.get(n) == 1:
                return stack[stack.index(n):] + [n]
            if n not in state:
                c = visit(n, stack)
                if c:
                    return c
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(edges):
        if m not in state:
            c = visit(m, [])
            if c:
                return c
    return None


def check(root):
    errors = []
    edges = {}
    for path in sources(root):
        part = part_of(path)
        if part is None:
            errors.append("%s: in no part of the floors (scripts/check_includes.py PARTS)" % path)
            continue
        allowed_parts, allowed_third = PARTS[part][1], PARTS[part][2]
        with open(os.path.join(root, path), errors="replace") as f:
            for no, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                kind, name = m.groups()
                where = "%s:%d" % (path, no)
                if kind == "<":
                    if any(fnmatch.fnmatch(name, p) for p in THIRD_PARTY) and \
                            not any(fnmatch.fnmatch(name, p) for p in allowed_third):
                        errors.append("%s: includes <%s>, a third-party header the %s part may not use" %
                                      (where, name, part))
                    continue
                if "/" not in name:
                    if name in GENERATED or os.path.exists(os.path.join(root, os.path.dirname(path), name)):
                        continue
                    errors.append('%s: includes "%s", which is not beside it' % (where, name))
                    continue
                target = part_of(name)
                if target is None:
                    errors.append('%s: includes "%s", outside the floors' % (where, name))
                    continue
                if (path, name) == MEETING_POINT:
                    continue
                if target not in allowed_parts:
                    errors.append('%s: includes "%s": the %s part may use only %s' %
                                  (where, name, part, ", ".join(sorted(allowed_parts))))
                    continue
                if part == "adapters" and target == "adapters" and adapter_of(name) != adapter_of(path) \
                        and module(name) not in SHARED_ADAPTER_MODULES:
                    errors.append('%s: includes "%s": an adapter sees no other adapter' % (where, name))
                    continue
                if module(name) != module(path):
                    edges.setdefault(module(path), set()).add(module(name))
    cycle = find_cycle(edges)
    if cycle:
        errors.append("modules include each other in a circle: %s" % " -> ".join(cycle))
    return errors


def test_floor(root, path):
    """The floors a file under tests/ names in its floor line (a list), or None."""
    with open(os.path.join(root, path), errors="replace") as f:
        for line in f:
            m = FLOOR_LINE.match(line)
            if m:
                return m.group(1).split()
    return None


def check_tests(root):
    errors = []
    floors_of = {}
    files = []
    for d, _, names in os.walk(os.path.join(root, "tests")):
        for f in sorted(names):
            if f.endswith((".c", ".h")):
                path = os.path.relpath(os.path.join(d, f), root)
                files.append(path)
                floors_of[path] = test_floor(root, path)
    for path in files:
        floors = floors_of[path]
        if not floors or any(f not in TEST_FLOORS for f in floors):
            errors.append('%s: no "/* floor: ... */" line naming %s' % (path, " or ".join(TEST_FLOORS)))
            continue
        allowed = set().union(*(TEST_FLOORS[f] for f in floors))
        with open(os.path.join(root, path), errors="replace") as f:
            for no, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m or m.group(1) != '"':
                    continue
                name = m.group(2)
                if "/" not in name:
                    if name in GENERATED:
                        target = {GENERATED[name]}
                    elif os.path.exists(os.path.join(root, os.path.dirname(path), name)):
                        continue
                    else:
                        errors.append('%s:%d: includes "%s", which is not beside it' % (path, no, name))
                        continue
                elif name.startswith("tests/"):
                    names = floors_of.get(name)
                    if names is None:
                        errors.append('%s:%d: includes "%s", which is not a test file' % (path, no, name))
                        continue
                    target = set().union(*(TEST_FLOORS.get(f, {f}) for f in names))
                else:
                    extra = [p for folder, p in EXTRA_PARTS.items() if name.startswith(folder + "/")]
                    part = extra[0] if extra else part_of(name)
                    if part is None:
                        errors.append('%s:%d: includes "%s", outside the floors' % (path, no, name))
                        continue
                    target = {part}
                if not target <= allowed:
                    errors.append('%s:%d: includes "%s": a test of the %s floor may use only %s' %
                                  (path, no, name, " ".join(floors), ", ".join(sorted(allowed))))
    return errors


def main(argv):
    if len(argv) > 2:
        print("usage: scripts/check_includes.py [ROOT]", file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if not os.path.isdir(os.path.join(root, "core")):
        print("check_includes.py: %s: no core/ folder" % root, file=sys.stderr)
        return 2
    errors = check(root)
    if os.path.isdir(os.path.join(root, "tests")):
        errors += check_tests(root)
    for e in errors:
        print(e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
