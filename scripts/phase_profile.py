#!/usr/bin/env python3
"""A HOT frame by phase at two scales, and which costs grow faster than the
particle count (issue 18, results/phase-profile).

    python3 scripts/phase_profile.py SMALL_DIR[,SMALL_DIR...] LARGE_DIR[,LARGE_DIR...]

Repeated runs of a scale, comma-separated, give the median and, in
brackets, the range of each cost. Each directory holds one `mpmbench run` (steps.csv, run.json), elapsed.txt
(the run's wall-clock seconds, GNU time's %e) and samples.csv, the perf
sample count per function of the same run (`perf report --no-children
--sort symbol -F sample,symbol`, written as `symbol,samples`). The phases
come from steps.csv (seconds summed over the steps); the particle sort and
the grid build, which the P2G phase does not separate, are the steps' wall
time times their share of the samples (both threads); the scene's set-up
and sampling is the run's elapsed time before and after the steps. Costs are given per
particle and step (microseconds), and the last column is the large run's
cost per particle and step over the small run's: 1 means the cost grows
like the particle count, above 1 faster. Solve and line search are also
given per outer iteration, since the number of iterations a step changes
with the resolution. Prints a markdown table."""
import csv
import json
import statistics
import sys

PHASES = [("p2g_s", "P2G phase (sort, grid, weights, transfer, problem setup)"),
          ("assemble_s", "assembly (tangent, pattern, Hessian)"),
          ("setup_s", "multigrid setup (Galerkin, single copies)"),
          ("solve_s", "solve (V-cycles, L-BFGS)"),
          ("linesearch_s", "line search (energy, gradient)"),
          ("g2p_s", "G2P and end of step")]

# functions of the P2G phase that perf separates (prefix match)
SORT = ("radix_sort", "particles_permute", "sort_particles", "compute_bases", "permute_field")
GRID = ("grid_build", "node_coloring_build", "reset_hash", "block_insert")


def load(d):
    steps = list(csv.DictReader(open(f"{d}/steps.csv")))
    run = json.load(open(f"{d}/run.json"))
    samples = {r["symbol"]: float(r["samples"]) for r in csv.DictReader(open(f"{d}/samples.csv"))}
    return steps, run, samples


def share(samples, prefixes):
    total = sum(samples.values())
    part = sum(v for k, v in samples.items() if k.startswith(prefixes))
    return part / total if total else 0.0


def costs(d):
    steps, run, samples = load(d)
    n_steps = len(steps)
    particles = float(steps[0]["particles"])
    iters = sum(float(s["outer_iters"]) for s in steps)
    tot = {k: sum(float(s[k] or 0) for s in steps) for k, _ in PHASES}
    wall = sum(float(s["wall_s"]) for s in steps)
    per = 1e6 / (particles * n_steps)
    out = {k: tot[k] * per for k, _ in PHASES}
    # sort and grid build: their share of all samples, as seconds of the steps' wall time
    out["sort"] = share(samples, SORT) * wall * per
    out["grid"] = share(samples, GRID) * wall * per
    out["wall_s"] = wall * per
    out["solve_per_iter"] = tot["solve_s"] / iters * 1e6 / particles
    out["ls_per_iter"] = tot["linesearch_s"] / iters * 1e6 / particles
    # scene loading and sampling, once: the elapsed time outside the steps
    out["sampling_s"] = float(open(f"{d}/elapsed.txt").read().split()[0]) - wall
    out.update(particles=particles, steps=n_steps, iters=iters, scale=run.get("scale"), threads=run.get("threads"))
    return out


def runs(arg):
    """Median and range of each cost over the comma-separated run directories."""
    cs = [costs(d) for d in arg.split(",")]
    med = dict(cs[0])
    for k, v in cs[0].items():
        if isinstance(v, float) and k not in ("particles", "iters"):
            vals = sorted(c[k] for c in cs)
            med[k] = statistics.median(vals)
            med[k + "_range"] = (vals[0], vals[-1])
    med["n_runs"] = len(cs)
    return med


def cell(c, k, fmt):
    lo, hi = c[k + "_range"]
    return f"{c[k]:{fmt}}" + (f" ({lo:{fmt}}-{hi:{fmt}})" if c["n_runs"] > 1 else "")


def main(argv):
    if len(argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    a, b = runs(argv[1]), runs(argv[2])
    print(f"| per particle and step (us) | scale {a['scale']:g} ({int(a['particles']):,} particles, "
          f"{a['steps']} steps, {int(a['iters'])} iterations) | scale {b['scale']:g} "
          f"({int(b['particles']):,}, {b['steps']}, {int(b['iters'])}) | growth |")
    print("|---|---:|---:|---:|")
    rows = [("wall_s", "**whole step**")] + [(k, name) for k, name in PHASES] + [
        ("sort", "of P2G: particle sort (radix sort, permutation)"),
        ("grid", "of P2G: grid build (blocks, node ids, colouring)"),
        ("solve_per_iter", "solve, per outer iteration"),
        ("ls_per_iter", "line search, per outer iteration")]
    for k, name in rows:
        print(f"| {name} | {cell(a, k, '.3f')} | {cell(b, k, '.3f')} | {b[k] / a[k]:.2f} |")
    print(f"| scene set-up and sampling, once (s) | {cell(a, 'sampling_s', '.2f')} | {cell(b, 'sampling_s', '.2f')} | "
          f"{(b['sampling_s'] / b['particles']) / (a['sampling_s'] / a['particles']):.2f} (per particle) |")
    print(f"\nMedians of {a['n_runs']} and {b['n_runs']} runs (range in brackets); growth = large / small.")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
