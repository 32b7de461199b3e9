#!/usr/bin/env python3
"""Fills the numbers quoted in the documentation from the committed results.

Markdown files carry markers around every number taken from a study:

    HOT is the fastest on <!-- n:scenes.hot_fastest_summary -->7 of 13<!-- /n --> scenes

The key after "n:" names a function below, which computes the text from the
files in results/ (report.csv, cells.csv, check.csv, wp.csv, provenance.json,
mg_levels.csv); the text between the markers is its value. The markers are
HTML comments, so they do not show in rendered markdown.

    python3 scripts/fill_numbers.py           rewrite every marker's text
    python3 scripts/fill_numbers.py --check   exit 1 and list the markers whose
                                              text differs from the results
    python3 scripts/fill_numbers.py --list    print every key and its value

Trust rules. Every key records the studies it reads. A number may be quoted
as current (`n:`) only when every study it reads is current (no solver of it
is stale: scripts/study_status.py), none of the rows it reads ran on a busy
machine (machine_busy), and, for a key that ranks solvers (RANKING), every
study it reads has at least two runs of each cell. Any other number is
history: it is quoted with an `h:` marker,

    HOT was <!-- h:stiffness.hot_geomean -->1.84<!-- /n -->x as fast as PN-PCG

and its section (from the heading before it to the next) carries the status
of every study it reads, a generated marker

    <!-- s:stiffness -->stiffness: build 7ab7cbd, ... stale ...<!-- /n -->

An `n:` marker whose number is not current, an `h:` marker without its
studies' status in its section, and an `h:` marker whose number is current
(quote it as `n:`) are errors. Every study that is not current says so on the
first line of its page (results/STUDY/README.md, else report.md) with its
status marker (--write puts it there). Staleness is judged by the build at
MPM_BINARY (default build/mpmbench).

Files: README.md, results/README.md, docs/*.md and the study pages
results/*/README.md and report.md, or the files given after the
mode (`--check FILE ...`). A marker with an unknown key,
or a key whose data is missing, is an error in every mode. The test suite runs
--check (tests/matrix/test_fill_numbers.sh), so a regenerated report that
changes a quoted number fails it until this script is rerun, and a number
typed by hand into a marker fails it at once.
"""
import csv
import glob
import json
import math
import os
import re
import statistics
import sys
import types

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import setting_table  # noqa: E402
import study_status  # noqa: E402
import matrix_report  # noqa: E402
import paper_scale_table  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "results")
MARKER = re.compile(r"<!-- ([nhs]):([A-Za-z0-9_.+-]+) -->(.*?)<!-- /n -->", re.S)
HEADING = re.compile(r"^(#{1,6}) ", re.M)
PAPER_SCENES = ["twist", "boxes", "donut", "armacat-soft", "armacat-stiff", "chain", "boards", "wheel",
                "faceless", "sauce"]


class Missing(Exception):
    pass


# ---- reading ---------------------------------------------------------------

_cache = {}
# what the key being computed reads: its studies (doubts() judges each as a whole)
_reading = {"studies": set()}


def reads(study):
    _reading["studies"].add(study)


def table(study, name):
    reads(study)
    path = os.path.join(RESULTS, study, name)
    if path not in _cache:
        if not os.path.exists(path):
            raise Missing(f"results/{study}/{name} does not exist")
        with open(path, newline="") as f:
            _cache[path] = list(csv.DictReader(f))
    return _cache[path]


def rows(study, name="report.csv", **where):
    """Rows of a CSV whose columns equal the given values."""
    out = [r for r in table(study, name) if all(r.get(k) == v for k, v in where.items())]
    if not out:
        raise Missing(f"results/{study}/{name}: no row with {where}")
    return out


def one(study, name="report.csv", **where):
    r = rows(study, name, **where)
    if len(r) != 1:
        raise Missing(f"results/{study}/{name}: {len(r)} rows with {where}, expected one")
    return r[0]


def num(r, col):
    try:
        v = float(r[col])
    except (KeyError, ValueError):
        raise Missing(f"column {col} is missing or not a number in {r}")
    return v


def summary(study):
    """DIR/summary.json, the report's answer in numbers (scripts/matrix_report.py)."""
    reads(study)
    path = os.path.join(RESULTS, study, "summary.json")
    if path not in _cache:
        if not os.path.exists(path):
            raise Missing(f"results/{study}/summary.json does not exist (rerun mpmbench matrix report)")
        with open(path) as f:
            _cache[path] = json.load(f)
    return _cache[path]


def solver_summary(study, solver):
    s = summary(study).get("solvers", {})
    if solver not in s:
        raise Missing(f"results/{study}/summary.json has no solver {solver}")
    return s[solver]


def provenance(study):
    reads(study)
    path = os.path.join(RESULTS, study, "provenance.json")
    if not os.path.exists(path):
        raise Missing(f"results/{study}/provenance.json does not exist")
    with open(path) as f:
        p = json.load(f)
    inv = p.get("invocations") or []
    if not inv:
        raise Missing(f"results/{study}/provenance.json has no invocation")
    return inv


# ---- formatting ------------------------------------------------------------

def sig(v, digits=3):
    """v with `digits` significant digits, plain notation where short."""
    if v == 0 or not math.isfinite(v):
        return f"{v:g}"
    e = math.floor(math.log10(abs(v)))
    if -4 <= e < 6:
        return f"{v:.{max(digits - 1 - e, 0)}f}"
    return f"{v:.{digits - 1}e}"


def grouped(n):
    return f"{int(round(n)):,}"


def span(values, digits=3, sep="-"):
    return f"{sig(min(values), digits)}{sep}{sig(max(values), digits)}"


def of(k, n):
    return f"{k} of {n}"


# ---- the numbers -------------------------------------------------------------

def cells_ok(study):
    """Cell runs that ended ok, as the report counts them."""
    sm = summary(study)
    return of(sm.get("status", {}).get("ok", 0), sm["cells"])


def fastest(study, solver):
    """Cases where the solver is faster than every other by more than the noise (summary.json)."""
    s = solver_summary(study, solver)
    return of(s["fastest_in"], s["fastest_of"])


def geomean(study, solver):
    return sig(solver_summary(study, solver)["speedup_geomean"])


def speedup_range(study, solver):
    s = solver_summary(study, solver)
    return f"{sig(s['speedup_min'])}-{sig(s['speedup_max'])}"


def cells_total_minutes(study):
    return f"{sum(num(r, 'elapsed_s') for r in table(study, 'cells.csv')) / 60:.0f}"


def run_date(study):
    return provenance(study)[0]["start_time"][:10]


def run_dates(study):
    """The first and last day a study's runs started on ("D1 to D2", or one day), as its status line gives them."""
    reads(study)
    dates = study_state(study).get("dates") or []
    if not dates:
        raise Missing(f"results/{study}: no run records its date")
    return " to ".join(sorted(set(dates)))


def run_cpu(study):
    p = provenance(study)[0]
    return f"{p['cpu_model']}, {p['cores_online']} cores"


def scenes_speedup(solver, scenes):
    return span([num(one("scenes-bench", scene=s, solver=solver), "speedup_total") for s in scenes])


def scenes_particles_max():
    return grouped(max(num(r, "particles") for r in table("scenes-bench", "cells.csv")))


def scenes_count(col):
    return str(len({r[col] for r in table("scenes-bench", "report.csv")}))


def stiffness_speedup(solver, modulus):
    return sig(num(one("stiffness", case=f"bar3 stiffness={modulus}", solver=solver), "speedup_total"))


def stiffness_iters(solver):
    lo = num(one("stiffness", case="bar3 stiffness=1e+05", solver=solver), "outer_iters")
    hi = num(one("stiffness", case="bar3 stiffness=1e+11", solver=solver), "outer_iters")
    return f"{lo:.0f} to {hi:.0f}"


def clearly_faster(a, b):
    """Report row a's s/frame is below row b's by more than the noise: the
    report's own rule (matrix_report.clearly_faster: with repeats the min-max
    ranges of the runs do not overlap, else more than its 1.1x floor), on
    report.csv rows."""
    def cell(r):
        return types.SimpleNamespace(runs=range(int(num(r, "runs"))), lo=num(r, "s_per_frame_min"),
                                     hi=num(r, "s_per_frame_max"), s_per_frame=num(r, "s_per_frame"))
    return matrix_report.clearly_faster(cell(a), cell(b))


def scenes_hot_not_fastest(what="list"):
    """The scenes of scenes-bench where another solver is faster than HOT by
    more than the noise (clearly_faster): that solver and by how much (ratio
    of medians), or HOT's L-BFGS iterations against PN-PCG's Newton
    iterations there."""
    by = {}
    for r in table("scenes-bench", "report.csv"):
        if r["status"] == "ok" and r["worst_status"] == "converged" and r["machine_busy"] == "0":
            by.setdefault(r["scene"], {})[r["solver"]] = r
    out = []
    for sc in sorted(by):
        d = by[sc]
        if "hot" not in d:
            continue
        best = min(d, key=lambda s: num(d[s], "s_per_frame"))
        if best != "hot" and clearly_faster(d[best], d["hot"]):
            ratio = num(d["hot"], "s_per_frame") / num(d[best], "s_per_frame")
            if what == "iters":
                out.append(f"{sc} {num(d['hot'], 'outer_iters'):.0f} against {num(d['pn-pcg'], 'outer_iters'):.0f}")
            else:
                out.append(f"{sc} ({best}, {sig(ratio, 3)}x faster)")
    if not out:
        raise Missing("results/scenes-bench: HOT is within the noise of the fastest on every scene")
    return ", ".join(out)


def stiffness_ratio(fast, slow, modulus):
    """slow's s/frame over fast's on bar3 at one middle-segment modulus."""
    a = num(one("stiffness", case=f"bar3 stiffness={modulus}", solver=slow), "s_per_frame")
    b = num(one("stiffness", case=f"bar3 stiffness={modulus}", solver=fast), "s_per_frame")
    return sig(a / b, 3)


def wp_err_h_range(eps):
    vals = [float(r["err_h_median"]) for r in table("work-precision", "wp.csv")
            if r["status"] == "ok" and r["eps"] and float(r["eps"]) == eps and r["err_h_median"]]
    if not vals:
        raise Missing(f"results/work-precision/wp.csv: no ok row at eps {eps}")
    return f"{sig(min(vals), 2)} to {sig(max(vals), 2)}"


def wp_err_h_spread(eps):
    """The largest ratio of median err_h between two solvers on one case at this eps."""
    by = {}
    for r in table("work-precision", "wp.csv"):
        if r["status"] == "ok" and r["eps"] and float(r["eps"]) == eps and r["err_h_median"]:
            by.setdefault(r["case"], []).append(float(r["err_h_median"]))
    ratios = [max(v) / min(v) for v in by.values() if len(v) > 1 and min(v) > 0]
    if not ratios:
        raise Missing("results/work-precision/wp.csv: no case with two solvers")
    return f"{max(ratios):.0f}"


DEC_SCENES = ("bar3", "twist", "faceless", "armacat-stiff")


def dec_spread(study, solver, eps):
    """The spread across the scenes of results/STUDY (decrement, decrement-fine:
    the same matrix at two scales) of the median per-step err_h of one solver
    spec at one eps (max/min), with its range."""
    vals = [float(r["err_h_median"]) for r in table(study, "wp.csv")
            if r["case"] in DEC_SCENES and r["solver"] == solver and r["status"] == "ok" and r["eps"]
            and float(r["eps"]) == eps and r["err_h_median"]]
    if len(vals) < 2 or min(vals) <= 0:
        raise Missing(f"results/{study}/wp.csv: fewer than two scenes for {solver} at eps {eps}")
    return f"{max(vals) / min(vals):.0f}x ({sig(min(vals), 2)} to {sig(max(vals), 2)}, {len(vals)} scenes)"


def particle_span(study):
    """The particle counts of a study's cells, "A to B" (one number when they agree)."""
    parts = [num(r, "particles") for r in table(study, "cells.csv")]
    lo, hi = grouped(min(parts)), grouped(max(parts))
    return lo if lo == hi else f"{lo} to {hi}"


def dec_egap_per_eps_max(study):
    """The largest median e_gap / eps of the decrement-stopped cells of
    results/STUDY, with its cell: how far the rule's estimate missed."""
    rows = [r for r in table(study, "wp.csv")
            if r["solver"].endswith(":stop=decrement") and r["status"] == "ok" and r["e_gap_median"]]
    if not rows:
        raise Missing(f"results/{study}/wp.csv: no decrement-stopped cell")
    r = max(rows, key=lambda r: float(r["e_gap_median"]) / float(r["eps"]))
    return f"{sig(float(r['e_gap_median']) / float(r['eps']), 2)} (on {r['case']}, {r['solver']}, eps {r['eps']})"


def omp_wait_times(load, wait):
    """s/frame of results/omp-wait's runs of one wait setting under one load
    (idle runs only when the machine was quiet)."""
    v = [num(r, "s_per_frame") for r in rows("omp-wait", "runs.csv", load=load, wait=wait)
         if load != "idle" or r["machine_busy"] == "0"]
    if not v:
        raise Missing(f"results/omp-wait: no quiet {load} run of {wait}")
    return v


def omp_wait_median(load, wait):
    return statistics.median(omp_wait_times(load, wait))


def omp_wait_date():
    r = rows("omp-wait", "runs.csv")[0]
    with open(os.path.join(RESULTS, "omp-wait", r["dir"], "run.json")) as f:
        return json.load(f)["provenance"]["start_time"][:10]


def omp_wait_ratio(load, wait, base_load, base_wait):
    return sig(omp_wait_median(load, wait) / omp_wait_median(base_load, base_wait), 3)


def omp_wait_spread(load, wait):
    v = omp_wait_times(load, wait)
    return f"{sig(min(v), 3)}-{sig(max(v), 3)} s"


def check_passed(study):
    c = table(study, "check.csv")
    return of(sum(r["pass"] == "1" for r in c), len(c))


def smoke_converged():
    c = table("smoke-matrix", "cells.csv")
    return of(sum(r["status"] == "ok" and float(r["converged_fraction"]) == 1 for r in c), len(c))


def mls_cells(transfer):
    """mls-bench cells (not the reference runs) of one transfer that ended ok."""
    return [r for r in table("mls-bench", "cells.csv")
            if r.get("role", "") != "reference" and r["status"] == "ok"
            and ("transfer=mls" in r["set"]) == (transfer == "mls")]


def mls_pos_rms_range(transfer, solver=None):
    """The last frame's pos_rms (dx) against the APIC reference run, over the transfer's cells."""
    vals = []
    for r in mls_cells(transfer):
        if solver and r["solver"] != solver:
            continue
        with open(os.path.join(RESULTS, "mls-bench", "cells", r["id"], "frames.csv"), newline="") as f:
            vals.append(float(list(csv.DictReader(f))[-1]["pos_rms"]))
    if not vals:
        raise Missing("results/mls-bench: no ok cell with that transfer")
    return span(vals, 2, " to ")


def mls_time_ratio(solver):
    """MLS/APIC s/frame over the scenes, for one solver (cells that ran on a quiet machine)."""
    by = {}
    for t in ("apic", "mls"):
        for r in mls_cells(t):
            if r["solver"] == solver and r.get("machine_busy", "0") != "1":
                by[(r["scene"], t)] = float(r["s_per_frame"])
    ratios = [by[(sc, "mls")] / by[(sc, "apic")] for (sc, t) in by if t == "apic" and (sc, "mls") in by]
    if not ratios:
        raise Missing("results/mls-bench: no scene with both transfers timed on a quiet machine")
    return span(ratios, 3)


ALGEBRAIC = ("pn-amg-pcg", "lbfgs-amg", "pn-ml-pcg", "lbfgs-ml")


def baselines_lead(threads, what="geo"):
    """The fastest algebraic multigrid's s/frame over HOT's, per scene at one
    thread count (cells converged on a quiet machine): geometric mean and range."""
    by = {}
    for r in table("baselines", "cells.csv"):
        if (r["threads"] == str(threads) and r["status"] == "ok" and r["worst_solve_status"] == "converged"
                and r.get("machine_busy", "0") != "1"):
            by.setdefault(r["scene"], {})[r["solver"]] = float(r["s_per_frame"])
    ratios = []
    for sc, t in by.items():
        alg = [t[s] for s in ALGEBRAIC if s in t]
        if "hot" in t and alg:
            ratios.append(min(alg) / t["hot"])
    if not ratios:
        raise Missing(f"results/baselines: no scene with hot and an algebraic multigrid at {threads} thread{'s' if threads != 1 else ''}")
    return summarise(ratios, what)


def summarise(ratios, what):
    """Ratios over scenes as quoted: the range, the count, or the geometric mean."""
    if what == "range":
        return span(ratios, 3)
    if what == "n":
        return str(len(ratios))
    return sig(math.exp(sum(math.log(x) for x in ratios) / len(ratios)), 3)


def median_lead(study, pick, what="geo", threads=2):
    """results/STUDY with repeats: per scene, the fastest (by median s/frame
    over its converged, quiet runs) of the solvers `pick` accepts, over HOT's
    median; summarised over the scenes (summarise), or the count of scenes
    where no run of `pick`'s solvers converged ("failed")."""
    times, tried = {}, {}
    for r in table(study, "cells.csv"):
        if r["threads"] != str(threads) or not (pick(r["solver"]) or r["solver"] == "hot"):
            continue
        tried.setdefault(r["scene"], set()).add(r["solver"])
        if r["status"] == "ok" and r["worst_solve_status"] == "converged" and r.get("machine_busy", "0") != "1":
            times.setdefault((r["scene"], r["solver"]), []).append(float(r["s_per_frame"]))
    ratios, failed = [], 0
    for sc in sorted(tried):
        mine = [statistics.median(times[(sc, so)]) for so in tried[sc] if so != "hot" and (sc, so) in times]
        if not mine:
            failed += 1
        if (sc, "hot") in times and mine:
            ratios.append(min(mine) / statistics.median(times[(sc, "hot")]))
    if what == "failed":
        return str(failed)
    if not ratios:
        raise Missing(f"results/{study}: no scene with hot and the solvers asked at {threads} threads")
    return summarise(ratios, what)


def baselines_repeat_lead(threads, what="geo"):
    """baselines_lead from results/baselines-repeat: each cell's median over
    its repeats (converged, quiet runs) in place of one run."""
    return median_lead("baselines-repeat", lambda so: so in ALGEBRAIC, what, threads)


GAMG = ("pn-gamg-pcg", "lbfgs-gamg")


def petsc_baselines_over_hot(pick, what="geo", threads=2):
    """median_lead of results/petsc-baselines."""
    return median_lead("petsc-baselines", pick, what, threads)


def is_petsc_amg(solver):
    return solver in GAMG or ":petsc:pc_type=" in solver


def algt_adopted(form, what):
    """results/algebraic-tuning: the setting its adoption rule took for one
    preset's solver form (setting_table.adoption) and its geometric-mean ratio to
    the untuned default ("setting", "ratio"), or the count of settings that
    qualified ("winners")."""
    cells = [r for r in table("algebraic-tuning", "cells.csv") if r.get("role", "") != "reference"]
    decided = setting_table.adoption(cells, "variant")
    if setting_table.TUNED_PRESETS[form] not in decided:
        raise Missing(f"results/algebraic-tuning: no cells of {setting_table.TUNED_PRESETS[form]}")
    a = decided[setting_table.TUNED_PRESETS[form]]
    if what == "winners":
        return str(sum(1 for j in a["judged"] if j[4]))
    if what == "setting":
        return a["best"][0] if a["best"] else f"none (kept {a['first']})"
    if not a["best"]:
        raise Missing(f"results/algebraic-tuning: nothing adopted for {setting_table.TUNED_PRESETS[form]}")
    return sig(a["best"][1], 2)


def bos_lead(threads, what="geo"):
    """results/baselines-out-of-sample: per scene the fastest algebraic
    multigrid's median s/frame over HOT's (median_lead)."""
    return median_lead("baselines-out-of-sample", lambda so: so in ALGEBRAIC, what, threads)


def fig18_speedup(scene, solver="gast15"):
    return sig(num(one("gast15-fig18", scene=scene, solver=solver), "speedup_total"))


# The like-for-like Table 1 ran in two parts, each scene wholly on one machine; a part's numbers are
# never pooled with the other's (scripts/paper_scale_table.py), so every key names its part.
PAPER_PARTS = {"epyc": "paper-scale", "xeon": "paper-scale-xeon"}
PAPER_RIVALS = ["pn-pcg", "pn-pcg-mf", "pn-mgpcg", "lbfgs-h", "lbfgs-ml"]


def paper_part(tag):
    """results/paper-scale*'s part of one machine, as scripts/paper_scale_table.py reads it."""
    study = PAPER_PARTS[tag]
    reads(study)
    d = os.path.join(RESULTS, study)
    if d not in _cache:
        if not os.path.isfile(os.path.join(d, "cells.csv")):
            raise Missing(f"results/{study}/cells.csv does not exist")
        _cache[d] = paper_scale_table.Part(d)
    return _cache[d]


def paper_part_particles(tag):
    p = paper_part(tag)
    n = [num(c.row, "particles") for (sc, _), c in p.study[3].items() if sc in p.done]
    if not n:
        raise Missing(f"results/{PAPER_PARTS[tag]} has no finished scene")
    return f"{grouped(min(n))} to {grouped(max(n))}"


def paper_part_lead(tag, solver, what):
    """HOT's total speedup over `solver` on the part's scenes (over the sampled frames, medians of the
    runs): geometric mean, range, or the scenes it covers; pairs that met eps on a quiet machine only."""
    p = paper_part(tag)
    sp = {sc: s.total for sc, s in p.speed.get(solver, {}).items() if sc in p.done}
    if not sp:
        raise Missing(f"results/{PAPER_PARTS[tag]}: no scene times both hot and {solver}")
    if what == "geomean":
        return sig(matrix_report.geomean(list(sp.values())))
    if what == "range":
        return span(sp.values()) if len(sp) > 1 else sig(next(iter(sp.values())))
    return str(len(sp))


def paper_part_bounds(tag, solver):
    """HOT's lead over `solver` where a part has only its bound (one run stopped by a time limit): at
    least the bound's seconds over HOT's slowest run, per scene (scripts/paper_scale_table.py)."""
    p = paper_part(tag)
    out = [f"at least {sig(paper_scale_table.bound_speedups(b, p.study[3][(sc, 'hot')])[0])}x on {sc}"
           for (sc, so), b in sorted(p.bounds.items()) if so == solver and sc in p.done and not b.busy]
    return "; ".join(out) if out else "none"


def smoother_ratio(solver, what="geo"):
    """smoother-precision: mean s/frame of the single runs over that of the
    double runs per scene (quiet machine), geometric mean or range."""
    by = {}
    for r in table("smoother-precision", "cells.csv"):
        if r["solver"] == solver and r.get("machine_busy", "0") != "1" and r["status"] == "ok":
            by.setdefault((r["scene"], r["precision"]), []).append(num(r, "s_per_frame"))
    mean = lambda v: sum(v) / len(v)
    ratios = [mean(by[(sc, "single")]) / mean(v) for (sc, p), v in by.items() if p == "double" and (sc, "single") in by]
    if not ratios:
        raise Missing(f"results/smoother-precision has no pair of {solver} cells")
    if what == "range":
        return span(ratios, 2)
    return f"{math.exp(sum(math.log(x) for x in ratios) / len(ratios)):.2f}"


def hot_step_ratio():
    """results/hot-step: median s/frame of the old build over the new one."""
    rows = table("hot-step", "bar3-scale1.csv")
    med = lambda b: statistics.median(num(r, "frame_s") for r in rows if r["build"] == b)
    return f"{med('old') / med('new'):.2f}"


def table1_ratio(scene, slow, fast):
    a = num(one("gast15-table1", scene=scene, solver=slow), "s_per_frame")
    b = num(one("gast15-table1", scene=scene, solver=fast), "s_per_frame")
    return sig(a / b, 2)


def table3_iteration_ratio():
    ratios = []
    for r in rows("table3", solver="pn-sgs-pcg"):
        j = one("table3", case=r["case"], solver="pn-pcg")
        ratios.append(num(j, "linear_per_step") / num(r, "linear_per_step"))
    return span(ratios, 2)


def table3_speed():
    return span([num(r, "speedup_total") for r in rows("table3", solver="pn-sgs-pcg")], 2)


def foundation_mf():
    return sig(num(one("foundation", solver="pn-pcg-mf"), "speedup_total"))


def foundation_bench(key, digits=3):
    reads("foundation")
    path = os.path.join(RESULTS, "foundation", "bench.txt")
    if not os.path.exists(path):
        raise Missing("results/foundation/bench.txt does not exist")
    with open(path) as f:
        for line in f:
            if line.startswith(key + "="):
                return sig(float(line.split("=", 1)[1]), digits)
    raise Missing(f"results/foundation/bench.txt has no {key}=")


def fig8_blocks(solver, level):
    cell = one("fig8", "cells.csv", solver=solver)
    lv = rows("fig8", os.path.join("cells", cell["id"], "mg_levels.csv"), level=str(level))[0]
    return f"{float(lv['blocks_per_row_avg']):.0f}"


def dec_keys(prefix, study):
    """The decrement study's numbers, one set per scale (decrement, decrement-fine)."""
    return {
        f"{prefix}.cells": lambda: cells_ok(study),
        f"{prefix}.date": lambda: run_date(study),
        f"{prefix}.particles": lambda: particle_span(study),
        f"{prefix}.pn-pcg_cn_1e-8": lambda: dec_spread(study, "pn-pcg", 1e-8),
        f"{prefix}.pn-pcg_dec_1e-4": lambda: dec_spread(study, "pn-pcg:stop=decrement", 1e-4),
        f"{prefix}.hot_cn_1e-6": lambda: dec_spread(study, "hot", 1e-6),
        f"{prefix}.hot_dec_1e-4": lambda: dec_spread(study, "hot:stop=decrement", 1e-4),
        f"{prefix}.egap_per_eps_max": lambda: dec_egap_per_eps_max(study),
    }


NUMBERS = {
    "scenes.cells": lambda: cells_ok("scenes-bench"),
    "scenes.minutes": lambda: cells_total_minutes("scenes-bench"),
    "scenes.date": lambda: run_date("scenes-bench"),
    "scenes.cpu": lambda: run_cpu("scenes-bench"),
    "scenes.cores": lambda: str(provenance("scenes-bench")[0]["cores_online"]),
    "scenes.n_scenes": lambda: scenes_count("scene"),
    "scenes.n_solvers": lambda: scenes_count("solver"),
    "scenes.particles_max": scenes_particles_max,
    "scenes.hot_fastest_summary": lambda: fastest("scenes-bench", "hot"),
    "scenes.hot_tied": lambda: str(solver_summary("scenes-bench", "hot")["tied_fastest_in"]),
    "scenes.hot_geomean": lambda: geomean("scenes-bench", "hot"),
    "scenes.hot_range": lambda: speedup_range("scenes-bench", "hot"),
    "history.cells": lambda: cells_ok("scenes-history"),
    "history.date": lambda: run_date("scenes-history"),
    "history.hot_geomean": lambda: geomean("scenes-history", "hot"),
    "stiffness.hot_geomean": lambda: geomean("stiffness", "hot"),
    "scenes.hot_vs_pn-pcg_paper": lambda: scenes_speedup("hot", PAPER_SCENES),
    "scenes.pn-mgpcg_vs_pn-pcg_paper": lambda: scenes_speedup("pn-mgpcg", PAPER_SCENES),
    "scenes.pn-amg-pcg_vs_pn-pcg_all": lambda: scenes_speedup(
        "pn-amg-pcg", sorted({r["scene"] for r in table("scenes-bench", "report.csv")})),
    "choose.hot_not_fastest": scenes_hot_not_fastest,
    "choose.hot_not_fastest_iters": lambda: scenes_hot_not_fastest("iters"),
    "choose.soft_mf_over_hot": lambda: stiffness_ratio("pn-pcg-mf", "hot", "1e+05"),
    "choose.stiff_hot_over_mf": lambda: stiffness_ratio("hot", "pn-pcg-mf", "1e+09"),
    "choose.stiff_hot_over_mgpcg": lambda: stiffness_ratio("hot", "pn-mgpcg", "1e+09"),
    "stiffness.hot_vs_pn-pcg_1e5": lambda: stiffness_speedup("hot", "1e+05"),
    "mpi.cells": lambda: cells_ok("scenes-mpi2x1"),
    "mpi.date": lambda: run_date("scenes-mpi2x1"),
    "mpi.n_scenes": lambda: str(len({r["scene"] for r in table("scenes-mpi2x1", "cells.csv")})),
    "stiffness.cells": lambda: cells_ok("stiffness"),
    "stiffness.date": lambda: run_date("stiffness"),
    "stiffness.hot_vs_pn-pcg_1e9": lambda: stiffness_speedup("hot", "1e+09"),
    "stiffness.hot_vs_pn-pcg_1e11": lambda: stiffness_speedup("hot", "1e+11"),
    "stiffness.hot_iters": lambda: stiffness_iters("hot"),
    "stiffness.pn-pcg_iters": lambda: stiffness_iters("pn-pcg"),
    "wp.cells": lambda: cells_ok("work-precision"),
    "wp.date": lambda: run_date("work-precision"),
    "wp.err_h_range_at_1e-7": lambda: wp_err_h_range(1e-7),
    "wp.err_h_spread_at_1e-7": lambda: wp_err_h_spread(1e-7),
    **dec_keys("dec", "decrement"),
    **dec_keys("decf", "decrement-fine"),
    "ompwait.idle_spin10k_vs_default": lambda: omp_wait_ratio("idle", "spin10k", "idle", "omp_default"),
    "ompwait.idle_spin1k_vs_default": lambda: omp_wait_ratio("idle", "spin1k", "idle", "omp_default"),
    "ompwait.idle_passive_vs_default": lambda: omp_wait_ratio("idle", "passive", "idle", "omp_default"),
    "ompwait.busy_omp_default_vs_idle": lambda: omp_wait_ratio("one-core-busy", "omp_default", "idle", "omp_default"),
    "ompwait.idle_omp_default_spread": lambda: omp_wait_spread("idle", "omp_default"),
    "ompwait.busy_omp_default_spread": lambda: omp_wait_spread("one-core-busy", "omp_default"),
    "ompwait.busy_spin10k_vs_idle": lambda: omp_wait_ratio("one-core-busy", "spin10k", "idle", "spin10k"),
    "ompwait.idle_spin10k_spread": lambda: omp_wait_spread("idle", "spin10k"),
    "ompwait.busy_spin10k_spread": lambda: omp_wait_spread("one-core-busy", "spin10k"),
    "ompwait.busy_spin1k_vs_idle": lambda: omp_wait_ratio("one-core-busy", "spin1k", "idle", "spin1k"),
    "ompwait.idle_spin1k_spread": lambda: omp_wait_spread("idle", "spin1k"),
    "ompwait.busy_spin1k_spread": lambda: omp_wait_spread("one-core-busy", "spin1k"),
    "ompwait.busy_passive_vs_idle": lambda: omp_wait_ratio("one-core-busy", "passive", "idle", "passive"),
    "ompwait.idle_passive_spread": lambda: omp_wait_spread("idle", "passive"),
    "ompwait.busy_passive_spread": lambda: omp_wait_spread("one-core-busy", "passive"),
    "ompwait.idle_default_s": lambda: sig(omp_wait_median("idle", "omp_default"), 3),
    "ompwait.date": lambda: omp_wait_date(),
    "tut.date": lambda: run_date("tutorial-1t-one-core-busy"),
    "tut.cells": lambda: f"{cells_ok('tutorial-1t-idle')} and {cells_ok('tutorial-1t-one-core-busy')}",
    "ompwait.runs": lambda: f"{len(rows('omp-wait', 'runs.csv'))} runs",
    "stress.cells": lambda: cells_ok("stress"),
    "stress.date": lambda: run_date("stress"),
    "stress.passed": lambda: check_passed("stress"),
    "smoke.cells": lambda: cells_ok("smoke-matrix"),
    "smoke.date": lambda: run_date("smoke-matrix"),
    "smoke.converged": smoke_converged,
    "mls.cells": lambda: cells_ok("mls-bench"),
    "mls.date": lambda: run_date("mls-bench"),
    "mls.pos_rms_mls": lambda: mls_pos_rms_range("mls"),
    "mls.pos_rms_apic": lambda: mls_pos_rms_range("apic"),
    "mls.pos_rms_mls_gast15": lambda: mls_pos_rms_range("mls", "gast15"),
    "mls.pos_rms_apic_gast15": lambda: mls_pos_rms_range("apic", "gast15"),
    "mls.time_ratio_hot": lambda: mls_time_ratio("hot"),
    "base.cells": lambda: cells_ok("baselines"),
    "base.date": lambda: run_date("baselines"),
    "base.lead_2t": lambda: baselines_lead(2),
    "base.lead_2t_range": lambda: baselines_lead(2, "range"),
    "base.lead_2t_n": lambda: baselines_lead(2, "n"),
    "base.lead_1t": lambda: baselines_lead(1),
    "base.lead_1t_range": lambda: baselines_lead(1, "range"),
    "brep.date": lambda: run_date("baselines-repeat"),
    "brep.cells": lambda: cells_ok("baselines-repeat"),
    "brep.lead_2t_range": lambda: baselines_repeat_lead(2, "range"),
    "amgt.date": lambda: run_date("amg-tuning"),
    "amgt.cells": lambda: cells_ok("amg-tuning"),
    "mlt.date": lambda: run_date("ml-tuning"),
    "mlt.cells": lambda: cells_ok("ml-tuning"),
    "reuse.date": lambda: run_date("reuse"),
    "reuse.cells": lambda: cells_ok("reuse"),
    "base.repeat_lead_2t": lambda: baselines_repeat_lead(2),
    "base.repeat_lead_1t": lambda: baselines_repeat_lead(1),
    "mls.time_ratio_pn-pcg": lambda: mls_time_ratio("pn-pcg"),
    "gamgt.date": lambda: run_date("gamg-tuning"),
    "pb.date": lambda: run_date("petsc-baselines"),
    "pb.cells": lambda: cells_ok("petsc-baselines"),
    "pb.gamg_lead_2t": lambda: petsc_baselines_over_hot(lambda so: so in GAMG),
    "pb.gamg_lead_2t_range": lambda: petsc_baselines_over_hot(lambda so: so in GAMG, "range"),
    "pb.gamg_lead_2t_n": lambda: petsc_baselines_over_hot(lambda so: so in GAMG, "n"),
    "pb.gamg_failed_scenes": lambda: petsc_baselines_over_hot(lambda so: so in GAMG, "failed"),
    "pb.petsc_lead_2t": lambda: petsc_baselines_over_hot(is_petsc_amg),
    "pb.petsc_lead_2t_range": lambda: petsc_baselines_over_hot(is_petsc_amg, "range"),
    "pb.ml_lead_2t": lambda: petsc_baselines_over_hot(lambda so: so == "lbfgs-ml"),
    "pb.hot_petsc_over_hot": lambda: petsc_baselines_over_hot(lambda so: so == "hot-petsc"),
    "pb.hot_petsc_over_hot_range": lambda: petsc_baselines_over_hot(lambda so: so == "hot-petsc", "range"),
    "algt.date": lambda: run_date("algebraic-tuning"),
    "algt.cells": lambda: cells_ok("algebraic-tuning"),
    **{f"algt.{form}_adopted": (lambda form=form: algt_adopted(form, "setting")) for form in setting_table.TUNED_PRESETS},
    **{f"algt.{form}_over_untuned": (lambda form=form: algt_adopted(form, "ratio")) for form in setting_table.TUNED_PRESETS},
    **{f"algt.{form}_winners": (lambda form=form: algt_adopted(form, "winners")) for form in setting_table.TUNED_PRESETS},
    "bos.date": lambda: run_date("baselines-out-of-sample"),
    "bos.cells": lambda: cells_ok("baselines-out-of-sample"),
    "bos.lead_2t": lambda: bos_lead(2),
    "bos.lead_2t_range": lambda: bos_lead(2, "range"),
    "bos.lead_2t_n": lambda: bos_lead(2, "n"),
    "bos.lead_1t": lambda: bos_lead(1),
    "bos.lead_1t_range": lambda: bos_lead(1, "range"),
    **{f"paper.{tag}.cells": (lambda tag=tag: cells_ok(PAPER_PARTS[tag])) for tag in PAPER_PARTS},
    **{f"paper.{tag}.date": (lambda tag=tag: run_dates(PAPER_PARTS[tag])) for tag in PAPER_PARTS},
    **{f"paper.{tag}.minutes": (lambda tag=tag: cells_total_minutes(PAPER_PARTS[tag])) for tag in PAPER_PARTS},
    **{f"paper.{tag}.n_scenes": (lambda tag=tag: str(len(paper_part(tag).done))) for tag in PAPER_PARTS},
    **{f"paper.{tag}.scenes": (lambda tag=tag: ", ".join(paper_part(tag).done)) for tag in PAPER_PARTS},
    **{f"paper.{tag}.particles": (lambda tag=tag: paper_part_particles(tag)) for tag in PAPER_PARTS},
    **{f"paper.{tag}.hot_fastest": (lambda tag=tag: of(len(paper_scale_table.hot_rank(paper_part(tag)).alone),
                                                       len(paper_scale_table.hot_rank(paper_part(tag)).ranked)))
       for tag in PAPER_PARTS},
    **{f"paper.{tag}.hot_tied": (lambda tag=tag: ", ".join(paper_scale_table.hot_rank(paper_part(tag)).tied) or "none")
       for tag in PAPER_PARTS},
    **{f"paper.{tag}.{so}_bounds": (lambda tag=tag, so=so: paper_part_bounds(tag, so))
       for tag in PAPER_PARTS for so in PAPER_RIVALS},
    **{f"paper.{tag}.{so}_{what}": (lambda tag=tag, so=so, what=what: paper_part_lead(tag, so, what))
       for tag in PAPER_PARTS for so in PAPER_RIVALS for what in ("geomean", "range", "n")},
    "sp.cells": lambda: cells_ok("smoother-precision"),
    "sp.date": lambda: run_date("smoother-precision"),
    "sp.hot": lambda: smoother_ratio("hot"),
    "sp.hot_range": lambda: smoother_ratio("hot", "range"),
    "sp.mgpcg": lambda: smoother_ratio("pn-mgpcg"),
    "sp.gmg": lambda: smoother_ratio("lbfgs-gmg"),
    "hotstep.vs_27d85c7": hot_step_ratio,
    "fig18.cells": lambda: cells_ok("gast15-fig18"),
    "fig18.date": lambda: run_date("gast15-fig18"),
    "fig18.gast15_vs_semi_drop": lambda: fig18_speedup("snowball-drop"),
    "fig18.gast15_vs_semi_wall": lambda: fig18_speedup("snowball-wall"),
    "fig18.gast15_vs_semi_collide": lambda: fig18_speedup("snowball-collide"),
    "table1.cells": lambda: cells_ok("gast15-table1"),
    "table1.date": lambda: run_date("gast15-table1"),
    "table1.gast15-hot_over_hot_bar3": lambda: table1_ratio("bar3", "gast15-hot", "hot"),
    "table3.cells": lambda: cells_ok("table3"),
    "table3.date": lambda: run_date("table3"),
    "table3.sgs_fewer_iterations": table3_iteration_ratio,
    "table3.sgs_speed": table3_speed,
    "fig8.cells": lambda: cells_ok("fig8"),
    "fig8.date": lambda: run_date("fig8"),
    "fig8.hot_level0": lambda: fig8_blocks("hot", 0),
    "fig8.hot_level4": lambda: fig8_blocks("hot", 4),
    "fig8.gmg_level4": lambda: fig8_blocks("lbfgs-gmg", 4),
    "foundation.cells": lambda: cells_ok("foundation"),
    "foundation.date": lambda: run_date("foundation"),
    "foundation.mf_speedup": foundation_mf,
    "foundation.spmv_gbs": lambda: foundation_bench("spmv_gbs"),
    "foundation.spmv_stream_ratio": lambda: foundation_bench("spmv_stream_ratio", 2),
}


# Keys that rank solvers by time (a speed ratio, a fastest count, a lead):
# one run per cell cannot carry them. Iteration counts, accuracy and counts of
# cells are the same on every run and are not in this set.
RANKING = {k for k in NUMBERS if re.search(
    r"(fastest|tied|geomean|_range$|within|_vs_|time_ratio|lead_|_over_|^ompwait\.(idle|busy)|"
    r"^sp\.(hot|mgpcg|gmg)|^hotstep\.|^fig18\.gast15|_over_|sgs_speed|mf_speedup)", k)}


def value(key):
    """The key's text and what it read: (text, {studies})."""
    if key not in NUMBERS:
        raise Missing(f"unknown key '{key}' (keys: scripts/fill_numbers.py NUMBERS)")
    _reading["studies"] = set()
    text = NUMBERS[key]()
    return text, set(_reading["studies"])


# ---- trust -------------------------------------------------------------------

_status = {}


def binary():
    return os.environ.get("MPM_BINARY") or study_status.DEFAULT_BINARY


def study_state(study):
    """scripts/study_status.py's verdict on results/STUDY; a folder without
    cells.csv cannot be checked and is never current."""
    if study not in _status:
        d = os.path.join(RESULTS, study)
        if any(os.path.isfile(os.path.join(d, f)) for f in ("cells.csv", "runs.csv")):
            try:
                _status[study] = study_status.status(d, binary())
            except (RuntimeError, OSError) as e:
                raise Missing(f"results/{study}: its status cannot be judged: {e}")
        else:
            _status[study] = {"study": study, "cells": 0, "current": False, "no_cells": True, "busy_cells": 0,
                              "repeats": 0, "stale_solvers": []}
    return _status[study]


def status_text(study):
    """The one-line status of a study, the text of its s: marker."""
    s = study_state(study)
    if s.get("no_cells"):
        return (f"{study}: not a matrix study (no cells.csv or runs.csv), so its build, machine and solver definitions "
                f"are not recorded per run and it cannot be shown current: kept for history")
    when = " to ".join(sorted(set(s["dates"]))) if s["dates"] else "date not recorded"
    build = "+".join(s["builds"]) or "not recorded"
    machine = "/".join(s["machines"]) or "machine not recorded"
    cores = "/".join(str(c) for c in s["cores"])
    runs = f"{s['repeats']} run{'s' if s['repeats'] != 1 else ''} per cell"
    busy = f"{s['busy_cells']} busy cells" if s["busy_recorded"] else "machine load not recorded"
    if s["current"]:
        state = "current"
    elif not s["stale_solvers"]:
        state = (f"{s['cells_without_run_json']} of its {s['cells']} cells without their run.json, so it cannot be "
                 "shown current: kept for history")
    else:
        n = len(s["stale_solvers"])
        state = f"stale for {n} solver setting{'s' if n != 1 else ''} ({', '.join(s['stale_solvers'][:3])}" + \
                (", ..." if n > 3 else "") + "): kept for history"
    return (f"{study}: build {build}{' (modified tree)' if s['modified_tree'] else ''}, {when}, {machine}"
            f"{', ' + cores + ' cores' if cores else ''}, {runs}, {busy}; {state}")


# Keys that describe a study (when, where, what it covered), not a result of it.
DESCRIPTIVE = re.compile(r"\.(date|cpu|cores|minutes|n_scenes|n_solvers)$")


def doubts(key, studies):
    """Why the key's number is not a current one ([] when it is)."""
    out = []
    if DESCRIPTIVE.search(key):
        return out
    for st in sorted(studies):
        s = study_state(st)
        if not s["current"]:
            out.append(f"results/{st} is not current")
        if s.get("busy_cells"):
            out.append(f"results/{st} has {s['busy_cells']} cells that ran on a busy machine")
        if key in RANKING and s["repeats"] < 2:
            out.append(f"it ranks solvers by time and results/{st} has one run per cell")
    return out


def section_of(text, pos):
    """The section of text holding pos: from the heading before it to the next
    heading of the same or a higher level (its subsections are in it)."""
    heads = [(m.start(), len(m.group(1))) for m in HEADING.finditer(text)]
    before = [h for h in heads if h[0] <= pos]
    lo, level = before[-1] if before else (0, 0)
    hi = min([len(text)] + [p for p, lv in heads if p > pos and (level == 0 or lv <= level)])
    return lo, hi


def study_page(study):
    d = os.path.join(RESULTS, study)
    for name in ("README.md", "report.md"):
        if os.path.isfile(os.path.join(d, name)):
            return os.path.join(d, name)
    return None


def files():
    out = [os.path.join(ROOT, "README.md"), os.path.join(RESULTS, "README.md")]
    out += sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
    out += sorted(p for p in (study_page(d) for d in os.listdir(RESULTS)) if p)
    return [f for f in out if os.path.exists(f)]


def page_first_line(path, text):
    """A study page's first line: the study's status when it is not current."""
    rel = os.path.relpath(path, RESULTS).split(os.sep)
    if len(rel) != 2 or study_page(rel[0]) != path:
        return text, None
    study = rel[0]
    if study_state(study)["current"]:
        return text, None
    line = f"> <!-- s:{study} -->{status_text(study)}<!-- /n -->\n"
    first = text.split("\n", 1)[0]
    if first.startswith(f"> <!-- s:{study} -->"):
        return text, None
    return line + "\n" + text, f"{os.path.relpath(path, ROOT)}: its first line does not say the study is kept for history"


def check_file(path, text, problems, changed):
    """text with every marker refilled; problems and changes appended."""
    count = 0
    rel = os.path.relpath(path, ROOT)

    def repl(m):
        nonlocal count
        count += 1
        kind, key, old = m.group(1), m.group(2), m.group(3)
        try:
            if kind == "s":
                if key not in os.listdir(RESULTS):
                    raise Missing(f"no study results/{key}")
                new, studies = status_text(key), set()
            else:
                new, studies = value(key)
                why = doubts(key, studies)
                if kind == "n" and why:
                    problems.append(f"{rel}: {key} = {new}: not a current number ({'; '.join(why)}): quote it as "
                                    f"history (<!-- h:{key} -->) with its studies' status (<!-- s:STUDY -->) "
                                    f"in its section, or rerun the study")
                if kind == "h":
                    if not why:
                        problems.append(f"{rel}: {key} = {new} is current: quote it with <!-- n:{key} -->")
                    lo, hi = section_of(text, m.start())
                    for st in sorted(studies):
                        if f"<!-- s:{st} -->" not in text[lo:hi]:
                            problems.append(f"{rel}: {key} is history from results/{st}, whose status "
                                            f"(<!-- s:{st} -->) is not in its section")
        except Missing as e:
            problems.append(f"{rel}: {key}: {e}")
            return m.group(0)
        if new != old:
            changed.append(f"{rel}: {key}: '{old}' -> '{new}'")
        return f"<!-- {kind}:{key} -->{new}<!-- /n -->"

    new_text = MARKER.sub(repl, text)
    if path == os.path.join(RESULTS, "README.md"):  # the index gives every study's status
        for d in sorted(os.listdir(RESULTS)):
            if (os.path.isdir(os.path.join(RESULTS, d)) and d != "scenes" and not d.endswith(".new")
                    and f"<!-- s:{d} -->" not in new_text):
                problems.append(f"{rel}: results/{d} has no status line (<!-- s:{d} -->)")
    new_text, missing_line = page_first_line(path, new_text)
    if missing_line:
        changed.append(missing_line)
    return new_text, count


def main(argv):
    mode = argv[0] if argv else "--write"
    paths = [os.path.abspath(a) for a in argv[1:]] or files()
    if mode not in ("--write", "--check", "--list"):
        print(__doc__, file=sys.stderr)
        return 2
    if mode == "--list":
        bad = 0
        for k in NUMBERS:
            try:
                text, studies = value(k)
                why = doubts(k, studies)
                print(f"{k}: {text}" + (f"    [history: {'; '.join(why)}]" if why else ""))
            except Missing as e:
                print(f"{k}: ERROR {e}")
                bad = 1
        return bad
    problems, changed, markers = [], [], 0
    for path in paths:
        with open(path) as f:
            text = f.read()
        new_text, n = check_file(path, text, problems, changed)
        markers += n
        if mode == "--write" and new_text != text:
            with open(path, "w") as f:
                f.write(new_text)
    for p in problems:
        print(f"fill_numbers: {p}", file=sys.stderr)
    if mode == "--check":
        for c in changed:
            print(f"fill_numbers: stale: {c}", file=sys.stderr)
        if changed:
            print("fill_numbers: run python3 scripts/fill_numbers.py to update", file=sys.stderr)
        print(f"fill_numbers: {markers} markers, {len(changed)} stale, {len(problems)} errors", file=sys.stderr)
        return 1 if changed or problems else 0
    for c in changed:
        print(f"fill_numbers: updated {c}")
    print(f"fill_numbers: {markers} markers, {len(changed)} updated, {len(problems)} errors", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
