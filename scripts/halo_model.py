#!/usr/bin/env python3
"""The counted halo volumes of results/distributed/census.csv (mpmbench
decompose) as a report, and a latency-bandwidth model of strong scaling to
1,000 ranks built on them (docs/distributed.md, "The scaling model").

    scripts/halo_model.py CENSUS.csv [--study results/petsc-baselines] > census.md

What is counted (exact, per rank): owned particles and nodes, ghost nodes
(each halo exchange of a 3-vector moves 24 bytes per ghost node), the ranks
a rank exchanges with, and the Hessian blocks it adds to other ranks' rows.

What is modelled (stated assumptions, nothing timed across ranks):
- compute per step on R ranks = the step's measured time on 1 thread, split
  into particle phases (P2G, G2P, assembly, line search, the rest) scaled by
  the busiest rank's particle share and node phases (setup and solve)
  scaled by its node share; measured at the study's scale and scaled to the
  census's by the particle and node counts, with the iteration counts held
  as measured (multigrid counts change little with resolution; this is the
  model's main assumption);
- a halo exchange on level l costs alpha * neighbours + bytes_l / beta with
  bytes_l = 24 * ghosts / c^l (c = 4 for HOT's 2x coarsening, a surface
  shrinking 4x per level; 9 for aggregation's 3x), a global reduction
  2 alpha ceil(log2 R);
- exchanges per step from the algorithms as mpmbench runs them (EXCHANGES
  below), reading outer, linear, coarse iterations and line-search
  evaluations from the study's steps.csv (its timed frames, 1 thread,
  median over repeats);
- strong scaling only at rank counts the census counted (a scene ends
  where it has more ranks than node blocks); weak scaling to 1,000 ranks
  keeps each rank's load, halo and neighbours as counted at 16 ranks and
  grows only the reductions' depth (and holds iterations, as multigrid
  nearly does).
"""
import argparse
import csv
import math
import os
import statistics
import sys
from collections import defaultdict

NETWORKS = [("interconnect", 2e-6, 10e9), ("ethernet", 30e-6, 1.0e9)]  # name, alpha [s], beta [B/s]
RANKS = [2, 16, 128, 512]  # strong scaling: counted rank counts
WEAK_RANKS = [16, 128, 1000]
SOLVERS = ["hot", "lbfgs-ml", "pn-gamg-pcg"]


def load_census(path):
    by = defaultdict(lambda: defaultdict(list))
    for r in csv.DictReader(open(path)):
        by[r["scene"]][int(r["ranks"])].append({k: (v if k == "scene" else float(v)) for k, v in r.items()})
    return by


def census_rows(by):
    out = []
    for scene, per in by.items():
        for R, rs in sorted(per.items()):
            n, nodes = rs[0]["particles"], rs[0]["nodes"]
            ghosts = [r["ghost_nodes"] for r in rs]
            rows_all = sum(r["owned_row_blocks"] + r["ghost_row_blocks"] for r in rs)
            out.append({
                "scene": scene, "R": R, "particles": int(n), "nodes": int(nodes),
                "p_imb": max(r["owned_particles"] for r in rs) / (n / R),
                "n_imb": max(r["owned_nodes"] for r in rs) / (nodes / R),
                "halo_ratio": sum(ghosts) / nodes,
                "max_ghosts": int(max(ghosts)),
                "max_kb": 24 * max(ghosts) / 1e3,
                "neighbours": int(max(r["send_ranks"] + r["receive_ranks"] for r in rs)),
                "ghost_rows": sum(r["ghost_row_blocks"] for r in rs) / rows_all if rows_all else 0.0,
            })
    return out


def surface_fit(per):
    """a in mean ghosts per rank = a * (nodes / R)^(2/3), least squares in logs
    over R >= 2, and the exponent a free fit gives."""
    pts = []
    for R, rs in per.items():
        if R < 2:
            continue
        g = statistics.mean(r["ghost_nodes"] for r in rs)
        pts.append((math.log(rs[0]["nodes"] / R), math.log(g)))
    if len(pts) < 2:
        return None, None
    a = math.exp(statistics.mean(y - 2 / 3 * x for x, y in pts))
    mx, my = statistics.mean(x for x, _ in pts), statistics.mean(y for _, y in pts)
    slope = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
    return a, slope


def study_inputs(study):
    """Per (scene, solver) at 1 thread: medians over repeats of the per-step
    means of the timed frames' steps."""
    cells = list(csv.DictReader(open(os.path.join(study, "cells.csv"))))
    acc = defaultdict(list)
    for c in cells:
        if c["threads"] != "1" or c["solver"] not in SOLVERS or c["status"] != "ok":
            continue
        steps = [s for s in csv.DictReader(open(os.path.join(study, "cells", c["id"], "steps.csv")))
                 if int(s["frame"]) >= int(c["first_timed_frame"])]
        if not steps or any(s["status"] != "converged" for s in steps):
            continue
        stats = {s["key"]: s["value"] for s in csv.DictReader(open(os.path.join(study, "cells", c["id"], "inverse_stats.csv")))}
        k = len(steps)
        f = lambda col: sum(float(s[col]) for s in steps) / k
        particle_s = f("p2g_s") + f("g2p_s") + f("assemble_s") + f("linesearch_s")
        node_s = f("setup_s") + f("solve_s")
        acc[(c["scene"], c["solver"])].append({
            "scale": float(c["scale"]), "particles": float(steps[-1]["particles"]),
            "nodes": float(steps[-1]["active_nodes"]), "wall": f("wall_s"),
            "particle_s": particle_s + max(0.0, f("wall_s") - particle_s - node_s), "node_s": node_s,
            "outer": f("outer_iters"), "linear": f("linear_iters"), "inner": f("inner_iters"),
            "ls": f("ls_evals"), "levels": int(float(stats.get("levels", 1))),
        })
    return {k: {f: statistics.median(r[f] for r in v) for f in v[0]} for k, v in acc.items()}


def exchanges(solver, it):
    """(halo exchanges by level, reductions) of one step. Level 0 counts every
    exchange on the fine grid, in 3-vectors (P2G's 4 values and the CN
    scale's 1 count as 5/3 of one)."""
    L = int(it["levels"])
    per_level = defaultdict(float)
    reductions = 1.0  # the dt rule's maximum
    per_level[0] += 5 / 3 + 1  # P2G and the CN scale (halo sums), G2P (a halo copy)
    per_level[0] += it["outer"] + it["ls"]  # gradients (sums), line-search iterates (copies)
    reductions += it["outer"] + it["ls"]  # the stop rule, each energy
    if solver == "pn-gamg-pcg":
        cycles = it["linear"]
        per_level[0] += it["linear"]  # PCG's search direction
        reductions += 2 * it["linear"]
        smooth, coarsening = 2 * 2, 9  # Chebyshev degree 2, before and after
    else:
        cycles = it["outer"]
        reductions += 2 * 8 * it["outer"]  # L-BFGS's two loops over a window of 8, one dot product each
        if solver == "hot":
            smooth, coarsening = 2 * 16, 4  # one symmetric coloured GS sweep before and after: 16 colour passes each
        else:
            smooth, coarsening = 2 * 2, 9  # ML: Chebyshev, 2 sweeps
    for l in range(max(L - 1, 1)):
        per_level[l] += cycles * (smooth + 3)  # smoothing, residual, restriction, prolongation
    if solver == "hot":
        per_level[L - 1] += it["inner"]  # coarse CG: one product, two dot products each
        reductions += 2 * it["inner"]
    else:
        reductions += cycles  # the coarse direct solve gathered: one collective per cycle
    return per_level, reductions, coarsening


def model_row(solver, it, census_per, R, net, weak=False):
    """One rank count of the model: the compute of the busiest rank plus the
    communication, per step. Strong scaling reads the census at R ranks;
    weak scaling keeps every rank's load and halo as counted at 16 ranks
    (R / 16 copies of the scene side by side) and only the reductions'
    depth grows with R."""
    _, alpha, beta = net
    n_paper, nodes_paper = census_per[1][0]["particles"], census_per[1][0]["nodes"]
    particle_s = it["particle_s"] * n_paper / it["particles"]  # one step at the census's resolution, 1 thread
    node_s = it["node_s"] * nodes_paper / it["nodes"]
    rs = census_per[16 if weak else R]
    p_share = max(r["owned_particles"] for r in rs) / n_paper
    n_share = max(r["owned_nodes"] for r in rs) / nodes_paper
    ghosts = max(r["ghost_nodes"] for r in rs)
    k = max(r["send_ranks"] + r["receive_ranks"] for r in rs)
    compute = particle_s * p_share + node_s * n_share
    t1 = (particle_s + node_s) * (R / 16 if weak else 1)  # the whole problem on one rank
    per_level, reductions, c = exchanges(solver, it)
    comm = sum(count * (alpha * k + 24 * ghosts / c ** l / beta) for l, count in per_level.items())
    comm += reductions * 2 * alpha * math.ceil(math.log2(R))
    step = compute + comm
    return {"t1": t1, "step": step, "comm_frac": comm / step, "efficiency": t1 / (R * step),
            "exchanges": sum(per_level.values()), "reductions": reductions}


def model_section(by, study, out):
    """Writes the modelled scaling to out; returns {(scene, network): [(step s, solver), ...]} at
    each scene's largest counted rank count."""
    inputs = study_inputs(study)
    name = os.path.basename(os.path.normpath(study))
    w = lambda text="": out.append(text)
    w(f"## Scaling, modelled (iterations and 1-thread step times from results/{name})\n")
    w("Parallel efficiency T1 / (R T_R) and, in brackets, the share of a step spent communicating, per network "
      f"({', '.join(f'{n}: alpha {al * 1e6:g} us, beta {b / 1e9:g} GB/s' for n, al, b in NETWORKS)}; "
      "assumed values, not measured). Exchanges and reductions are per step. Strong: the scene at scale 1 "
      "on R ranks (counted volumes; '-' where the scene has fewer blocks than ranks). Weak: R/16 scenes' "
      "worth on R ranks, each rank loaded as at 16.\n")
    w("| scene | solver | exchanges | reductions | T1 [s/step] | network | "
      + " | ".join(f"strong {R}" for R in RANKS) + " | " + " | ".join(f"weak {R}" for R in WEAK_RANKS) + " |")
    w("|---|---|---:|---:|---:|---|" + "---:|" * (len(RANKS) + len(WEAK_RANKS)))
    best = defaultdict(list)
    fmt = lambda c: f"{100 * c['efficiency']:.0f} % ({100 * c['comm_frac']:.0f} %)" if c else "-"
    for scene in by:
        for solver in SOLVERS:
            it = inputs.get((scene, solver))
            if not it:
                continue
            for net in NETWORKS:
                strong = [model_row(solver, it, by[scene], R, net) if R in by[scene] else None for R in RANKS]
                weak = [model_row(solver, it, by[scene], R, net, weak=True) for R in WEAK_RANKS]
                first = strong[0]
                w(f"| {scene} | {solver} | {first['exchanges']:.0f} | {first['reductions']:.0f} | "
                  f"{first['t1']:.2f} | {net[0]} | " + " | ".join(fmt(c) for c in strong + weak) + " |")
                largest = max(R for R in by[scene] if R in RANKS)
                best[(scene, net[0], largest)].append((strong[RANKS.index(largest)]["step"], solver))
    w("\nFastest modelled step at the largest counted rank count (time per step, not efficiency, decides):\n")
    for (scene, net, R), v in sorted(best.items()):
        v.sort()
        w(f"- {scene}, {R} ranks, {net}: " + ", ".join(f"{s} {t * 1e3:.1f} ms" for t, s in v))
    without = sorted(set(by) - {s for s, _ in inputs})
    if without:
        w(f"\nNot modelled (no 1-thread cells of these scenes in results/{name}): {', '.join(without)}.")
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("census")
    ap.add_argument("--provenance", default=None, help="a file of 'key: value' lines on how the census was counted")
    ap.add_argument("--study", default=None, help="the study whose 1-thread cells give the step times and iterations")
    a = ap.parse_args()
    by = load_census(a.census)
    rows = census_rows(by)
    model = []
    best = model_section(by, a.study, model) if a.study else {}
    print("# Halo volumes, counted, and a scaling model\n")
    print("Generated by `scripts/distributed_census.sh` (`mpmbench decompose`, then `scripts/halo_model.py`); "
          "docs/distributed.md says what is counted and what is assumed.", end="")
    if a.provenance:
        prov = dict(line.rstrip("\n").split(": ", 1) for line in open(a.provenance) if ": " in line)
        print(f" Counted by {prov.get('counted by', '?')} on {prov.get('date', '?')}.", end="")
    print("\n")
    at16 = [r for r in rows if r["R"] == 16]
    worst16, best16 = max(at16, key=lambda r: r["halo_ratio"]), min(at16, key=lambda r: r["halo_ratio"])
    print(f"**Answer first.** Counted: at the paper's resolution split over 16 ranks, the ghost nodes are "
          f"{100 * best16['halo_ratio']:.0f} % ({best16['scene']}) to {100 * worst16['halo_ratio']:.0f} % "
          f"({worst16['scene']}) of the nodes, and the busiest rank sends at most "
          f"{max(r['max_kb'] for r in at16):.0f} kB per exchange of a 3-vector; cutting by particles leaves "
          f"nodes unbalanced by up to {max(r['n_imb'] for r in at16):.2f}x, which the solver phases (work per node) "
          "pay.", end="")
    if best:
        wins = defaultdict(int)
        for v in best.values():
            wins[min(v)[1]] += 1
        order = sorted(wins.items(), key=lambda kv: -kv[1])
        print(" Modelled (assumed networks, iteration counts as measured on one process): the fastest step at "
              "the largest counted rank count is " + ", ".join(f"{s}'s in {k} of {len(best)} scene-network pairs"
                                                             for s, k in order)
              + ". HOT turns latency-bound first: its symmetric coloured Gauss-Seidel needs one exchange per "
              "colour (16 a sweep) and its coarse CG one exchange and two reductions per iteration.")
    print("\n")
    print("## Counted volumes (the first step of each scene, scale 1)\n")
    print("| scene | particles | nodes | ranks | particles max/mean | nodes max/mean | ghosts / nodes | max ghosts "
          "| max kB per exchange | max neighbours | ghost-row share of Hessian blocks |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['scene']} | {r['particles']} | {r['nodes']} | {r['R']} | {r['p_imb']:.3f} | {r['n_imb']:.3f} | "
              f"{100 * r['halo_ratio']:.1f} % | {r['max_ghosts']} | {r['max_kb']:.1f} | {r['neighbours']} | "
              f"{100 * r['ghost_rows']:.1f} % |")
    print("\n## Surface law\n")
    print("Mean ghosts per rank against nodes per rank over every counted rank count from 2: the fitted exponent "
          "(2/3 for compact, cube-like pieces; lower while the pieces are slabs) and the coefficient a of "
          "ghosts = a (nodes/R)^(2/3).\n")
    print("| scene | exponent | a |")
    print("|---|---:|---:|")
    for scene, per in by.items():
        a_fit, slope = surface_fit(per)
        if a_fit:
            print(f"| {scene} | {slope:.2f} | {a_fit:.2f} |")
    if model:
        print()
        print("\n".join(model))


if __name__ == "__main__":
    sys.exit(main())
