#!/usr/bin/env python3
"""HOT's supplement Table 1 at the paper's particle counts, from a finished
run of experiments/matrices/paper-scale.json:

    python3 scripts/paper_scale_table.py results/paper-scale > results/paper-scale/table.md
    python3 scripts/paper_scale_table.py PART_DIR PART_DIR ... > table.md
    python3 scripts/paper_scale_table.py --out FILE PART_DIR ...   (FILE replaced only if the table is made)
    python3 scripts/paper_scale_table.py --rerun-bounds OLD_DIR NEW_DIR MPMBENCH

Each scene's whole animation is simulated once by HOT (the reference run,
which writes checkpoints); every cell then times the same three frames of it
(the matrix's sample_frames), restarted from those checkpoints, 3 runs a
cell. Per scene and solver this prints HOT's speedup as the paper's Table 1
defines it (HOT paper section 7.2): the solver's total time over HOT's
("total", here over the sampled frames, from the medians of the runs, with
the range over the runs) and the largest of the per-frame ratios ("max per
frame", over the sampled frames only, so at most the paper's maximum over
every frame). Then seconds per frame, iterations and peak memory, and how
far HOT's sampled frames stand for its whole animation (the reference run's
seconds per frame beside the sample's). A cell that did not meet eps on a
quiet machine is marked and left out of the summary, as the report does.

A solver too slow to time three times on a scene (a pair the matrix
excludes) can be given a bound instead: one `mpmbench run` of it from the
same checkpoints and sampled frames, stopped by --max-run-seconds, with its
--out in DIR/bounds/NAME/. Its seconds are a lower bound on its total over
the sample, so HOT's speedup over it is at least those seconds over HOT's
slowest run, and the table prints it as such. --rerun-bounds runs the
bounds of a study again into a rerun of it (scripts/reproduce.sh does).

Timings from two machines are never one study: every run of a folder must
name one CPU model, and every timed run one build, or the script stops. A
reference run gives the cells their states and the whole-animation column
only; it may come from another build (a build that can resume it, for a
reference longer than a session), which the table names, and then its
scene's "sampled / whole" ratio, which would compare two builds, is left
out. A matrix run in
parts on different machines, each scene wholly on one, is given as several
folders: one table, each scene's row naming its machine, and the summary
(geometric means, ranks) once per machine, never pooled.
"""
import contextlib
import glob
import json
import os
import statistics
import subprocess
import sys
import types

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import matrix_report as mr  # noqa: E402

HOT = "hot"
# HOT paper section 7.2, "on total timing", over whole animations on "consumer-level Intel CPU
# machines" (no core count stated); it states no range for the algebraic multigrid (lbfgs-ml).
PAPER_TOTAL = {"pn-pcg": "1.98-5.79", "pn-pcg-mf": "1.05-5.76", "pn-mgpcg": "2.26-10.67", "lbfgs-h": "1.03-4.79"}


def load(d):
    """The matrix's metadata, its scene order, the merged timed cells by (scene, solver) and
    the reference run of each scene."""
    meta, cells = mr.load(d)
    refs = {c.row["scene"]: c for c in cells if c.row.get("role") == "reference"}
    timed = {(c.row["scene"], c.solver): c for c in mr.merge_repeats([c for c in cells if c.row.get("role") != "reference"])}
    axes = (meta.get("matrix") or {}).get("axes", {})
    scenes = axes.get("scene") or list(dict.fromkeys(s for s, _ in timed))
    solvers = axes.get("solver") or list(dict.fromkeys(s for _, s in timed))
    return meta, scenes, solvers, timed, refs


class Bound:
    """One run of DIR/bounds/NAME/ (run.json, frames.csv): a solver timed on a scene's sampled
    frames from the reference's checkpoints and stopped by its time limit. spent: its seconds
    over the sample until then, a lower bound on its total; at: the frame (and the step count
    there) where it stopped; frame_time: frame -> seconds, the cut frame's a lower bound."""

    def __init__(self, path):
        self.path = path
        try:
            with open(os.path.join(path, "run.json")) as f:
                run = json.load(f)
        except (OSError, ValueError) as e:
            mr.die(f"{path}/run.json: {e}")
        frames = mr.read_csv(os.path.join(path, "frames.csv"))
        if not frames:
            mr.die(f"{path}/frames.csv: missing or empty")
        self.scene, self.solver = run.get("scene"), run.get("solver")
        self.eps, self.scale, self.threads = run.get("eps"), run.get("scale"), run.get("threads")
        ck = run.get("checkpoints") or {}
        self.sample_from, self.sample_frames = ck.get("sample_from") or "", ck.get("sample_frames") or ""
        self.limit = (run.get("limits") or {}).get("max_run_seconds") or 0.0
        self.overrides = run.get("overrides") or {}
        self.commit, self.machine = run_commit(run), run_machine(run)
        self.busy = bool((run.get("machine_load") or {}).get("machine_busy"))
        ran = [f for f in frames if int(mr.number(f.get("steps"), 0)) > 0]  # not the 0-step row of the frame after
        self.frame_time = {int(mr.number(f.get("frame"), -1)): mr.number(f.get("wall_s"), 0.0) for f in ran}
        self.spent = sum(self.frame_time.values())
        self.iters = tuple(sum(int(mr.number(f.get(k), 0)) for f in frames)
                           for k in ("outer_iters", "linear_iters", "inner_iters"))

        def stopped(f):  # the row of the frame the limit cut (its last step's solve, or the frame itself)
            return mr.frame_cut_short(f) or (f.get("status") == "timeout" and
                                             "--max-run-seconds" in (f.get("reason") or ""))
        cut = [f for f in ran if stopped(f)] or [f for f in frames if stopped(f)]
        self.cut = bool(cut)
        self.at = (int(mr.number(cut[0].get("frame"), -1)), int(mr.number(cut[0].get("steps"), 0))) if cut else None
        # the frames before the stop must have met eps: else the seconds are not those of reaching it
        self.failed = [f.get("frame") for f in frames if not stopped(f) and f.get("status") != "converged"]

    def check(self, hot, study_commit, study_machine):
        """Dies (one line, exit 2) unless the run times the same states as the study's cells of its
        scene: the reference's checkpoints, the sampled frames, eps, scale, threads, build and
        machine; and
        unless its time limit cut it short (a whole run is a cell of the matrix, not a bound)."""
        hot_overrides = hot.run.get("overrides") or {}
        want = {"sample_frames": hot.row.get("sample_frames"), "eps": mr.number(hot.row.get("eps")),
                "scale": mr.number(hot.row.get("scale")), "threads": int(mr.number(hot.row.get("threads"), 0)),
                "git_commit": study_commit, "cpu_model": study_machine, "overrides": hot_overrides}
        got = {"sample_frames": self.sample_frames, "eps": self.eps, "scale": self.scale, "threads": self.threads,
               "git_commit": self.commit, "cpu_model": self.machine, "overrides": self.overrides}
        for k, v in want.items():
            if got[k] != v:
                mr.die(f"{self.path}/run.json: {k} {got[k]!r}, but the study's {self.scene} cells ran with {v!r}")
        ref = f"cells/{hot.row.get('reference')}/checkpoints"
        if not self.sample_from.rstrip("/").endswith(ref):
            mr.die(f"{self.path}/run.json: checkpoints.sample_from {self.sample_from!r} is not the study's "
                   f"{self.scene} reference ({ref})")
        if not self.cut or not self.limit:
            mr.die(f"{self.path}/frames.csv: the run was not stopped by --max-run-seconds: "
                   "a whole run belongs in the matrix, not in bounds/")

    def text(self):
        frame, steps = self.at
        return (f"stopped by its limit of {mr.fmt(self.limit)} s in frame {frame}"
                + (f", step {steps} of it (counted from 1)" if steps else ", before its first step") + ", one run"
                + ("; busy" if self.busy else "") + (f"; frames not converged: {', '.join(self.failed)}"
                                                     if self.failed else ""))


def run_commit(run):
    """The build a run.json's provenance names (None when it names none)."""
    return ((run.get("provenance") or {}).get("build") or {}).get("git_commit")


def run_machine(run):
    """The CPU model a run.json's provenance names (None when it names none)."""
    return (run.get("provenance") or {}).get("cpu_model")


def study_one(cells, get, what):
    """The one value get(run.json) of every run of these cells (None when none names it); dies when
    there are several: timings from two builds, or two machines, are not one study."""
    values = {get(r.run) for c in cells for r in c.runs}
    values.discard(None)
    if len(values) > 1:
        mr.die(f"the cells ran on {len(values)} {what} ({', '.join(sorted(values))}): not one study")
    return values.pop() if values else None


def study_commit(cells):
    """The build every run of these cells ran; dies when there are several."""
    return study_one(cells, run_commit, "builds")


def study_machine(cells):
    """The CPU every run of these cells ran on; dies when there are several (run each machine's
    scenes into a folder of its own: several folders make one table as parts)."""
    return study_one(cells, run_machine, "machines")


def excluded(meta, scene, solver):
    """Does an exclude rule of the matrix (one of scene and solver only) drop this pair?"""
    def hits(rule, key, value):
        v = rule.get(key, value)
        return value in v if isinstance(v, list) else v == value
    rules = (meta.get("matrix") or {}).get("exclude") or []
    return any(set(r) <= {"scene", "solver"} and hits(r, "scene", scene) and hits(r, "solver", solver)
               for r in rules)


def load_bounds(d, timed):
    """{(scene, solver): Bound} of DIR/bounds/*/, each checked against the HOT cell of its scene."""
    root = os.path.join(d, "bounds")
    names = sorted(os.listdir(root)) if os.path.isdir(root) else []
    commit = study_commit(timed.values())
    machine = study_machine(timed.values())
    out = {}
    for name in names:
        b = Bound(os.path.join(root, name))
        hot = timed.get((b.scene, HOT))
        if hot is None:
            mr.die(f"{b.path}/run.json: scene {b.scene!r} has no timed {HOT} cell in {d}")
        if (b.scene, b.solver) in timed:
            mr.die(f"{b.path}/run.json: {b.scene}/{b.solver} is also a timed cell of the study: one or the other")
        b.check(hot, commit, machine)
        out[(b.scene, b.solver)] = b
    return out


def bound_speedups(bound, hot):
    """HOT's speedup over a bounded solver, at least: (total, largest per-frame ratio), each the
    bound's seconds over HOT's slowest run (so no run of HOT could make it smaller)."""
    n = len(hot.timed)
    total = bound.spent / max(r.s_per_frame * n for r in hot.runs)
    per = max((t / max(r.timed.get(k, float("inf")) for r in hot.runs)
               for k, t in bound.frame_time.items() if k in hot.timed), default=None)
    return total, per


def hot_speedups(study):
    """{solver: {scene: Speedup of HOT over it}} for the pairs whose cells both met eps on a
    quiet machine (Speedup.claimed), every solver but HOT; study: what load returns."""
    _, scenes, solvers, timed, _ = study
    out = {}
    for so in solvers:
        if so == HOT:
            continue
        for sc in scenes:
            h, o = timed.get((sc, HOT)), timed.get((sc, so))
            if h is None or o is None:
                continue
            sp = mr.Speedup(h, o)
            if sp.claimed():
                out.setdefault(so, {})[sc] = sp
    return out


def fastest(study, among):
    """{scene: the solvers of `among` tied for the fastest (the report's noise rule), or None}."""
    _, scenes, _, timed, _ = study
    out = {}
    for sc in scenes:
        r = mr.case_ranking([c for (s, so), c in timed.items() if s == sc and so in among])
        out[sc] = [c.solver for c in r["tied"]] if r else None
    return out


def span(xs):
    return f"{mr.fmt(min(xs))}-{mr.fmt(max(xs))}"


class Part:
    """One study folder of the matrix (one build, one machine): its cells, bounds and what they show.
    dir, machine, commit; study: what load returns; bounds; speed: hot_speedups; wins, unranked;
    done: scenes with every solver timed or bounded; missing, unbounded: what is left."""

    def __init__(self, d):
        self.dir = d
        self.study = load(d)
        meta, scenes, solvers, timed, refs = self.study
        ran = list(timed.values()) + list(refs.values())
        # one machine for every run; one build for the timed runs (a reference only gives them their states)
        self.machine, self.commit = study_machine(ran), study_commit(list(timed.values()))
        self.ref_builds = {sc: {run_commit(r.run) for r in c.runs} - {None} for sc, c in refs.items()}
        self.other_build = {sc: sorted(b)[0] for sc, b in self.ref_builds.items() if b and b != {self.commit}}
        self.present = {c.row["scene"] for c in ran}
        self.speed = hot_speedups(self.study)
        self.paper_set = [so for so in solvers if so == HOT or so in PAPER_TOTAL]
        self.wins = fastest(self.study, self.paper_set)
        self.bounds = load_bounds(d, timed)
        self.unranked = {}  # scene -> why a bound leaves its fastest open
        for (sc, so), b in self.bounds.items():
            if so in self.paper_set and self.wins.get(sc):
                best = timed[(sc, self.wins[sc][0])]
                if not b.spent / len(best.timed) > best.hi or b.busy or b.failed:
                    self.unranked[sc] = f"{so}'s bound does not show it slower than {best.solver}"
                    self.wins[sc] = None
        self.done = [sc for sc in scenes if all((sc, so) in timed or (sc, so) in self.bounds for so in solvers)]
        self.missing = [sc for sc in scenes if sc not in self.done and not all(
            (sc, so) in timed or excluded(meta, sc, so) for so in solvers)]
        self.unbounded = [f"{sc}/{so}" for sc in scenes for so in solvers
                          if sc not in self.done and sc not in self.missing and (sc, so) not in timed
                          and (sc, so) not in self.bounds]


def check_parts(parts):
    """Several parts make one table only when they ran one matrix on one build and no scene is in two
    of them (a scene's reference and cells come from one machine); dies otherwise."""
    first = parts[0]
    for p in parts[1:]:
        for what, get in (("matrix", lambda q: q.study[0].get("name")), ("solvers", lambda q: q.study[2]),
                          ("build", lambda q: q.commit)):
            if get(p) != get(first):
                mr.die(f"{p.dir}: {what} {get(p)!r}, but {first.dir} has {get(first)!r}: not parts of one study")
    seen = {}
    for p in parts:
        for sc in sorted(p.present):
            if sc in seen:
                mr.die(f"{p.dir}: scene {sc!r} is also in {seen[sc]}: a scene's runs come from one machine")
            seen[sc] = p.dir


def hot_rank(p):
    """HOT's place among the paper's solvers on the finished scenes of part p: the scenes ranked, and
    those where HOT was the fastest alone, tied for the fastest, or slower than another."""
    ranked = [sc for sc in p.done if p.wins.get(sc)]
    alone = [sc for sc in ranked if p.wins[sc] == [HOT]]
    tied = [sc for sc in ranked if HOT in p.wins[sc] and len(p.wins[sc]) > 1]
    lost = [sc for sc in ranked if HOT not in p.wins[sc]]
    return types.SimpleNamespace(ranked=ranked, alone=alone, tied=tied, lost=lost)


def summary(p, solvers):
    """The bullets of one part: HOT's rank among the paper's solvers, and its speedup over each."""
    _, _, _, timed, _ = p.study
    rank = hot_rank(p)
    ranked, alone, tied, lost = rank.ranked, rank.alone, rank.tied, rank.lost
    print(f"- Among the paper's solvers ({', '.join(p.paper_set)}) HOT was the fastest on {len(alone)} of "
          f"{len(ranked)} scenes "
          f"by more than the spread of the runs, tied for the fastest on {len(tied)}"
          + (f" ({', '.join(tied)})" if tied else "")
          + (f"; slower on {', '.join(f'{sc} (fastest: {p.wins[sc][0]})' for sc in lost)}" if lost else "")
          + (f"; unranked: {'; '.join(f'{sc} ({why})' for sc, why in p.unranked.items())}" if p.unranked else "")
          + ". The paper: HOT the fastest of these on all but two of its ten scenes.")
    for so in solvers:
        if so == HOT:
            continue
        sp = p.speed.get(so, {})
        bounded = [(sc, b) for (sc, o), b in p.bounds.items() if o == so and sc in p.done and not b.busy]
        if not sp and not bounded:
            continue
        tot = [s.total for s in sp.values()]
        per = [s.per for s in sp.values() if s.per]
        paper = f"; the paper: {PAPER_TOTAL[so]}x" if so in PAPER_TOTAL else "; the paper has no such solver"
        if len(tot) > 1:
            line = (f"- HOT against {so}: {mr.geomean(tot):.2f}x as fast in total (geometric mean over {len(tot)} "
                    f"scenes, {span(tot)}x), largest per-frame ratio {span(per)}x")
        elif tot:
            line = (f"- HOT against {so}: {mr.fmt(tot[0])}x as fast in total (one scene, {next(iter(sp))}), "
                    f"largest per-frame ratio {span(per) if len(per) != 1 else mr.fmt(per[0])}x")
        else:
            line = f"- HOT against {so}:"
        for sc, b in bounded:
            total, fr = bound_speedups(b, timed[(sc, HOT)])
            line += (f"{';' if tot else ''} on {sc} at least {mr.fmt(total)}x in total and {mr.fmt(fr)}x "
                     f"on a frame ({b.text()})")
        print(line + f"{paper}.")
    if p.unbounded:
        print(f"- Excluded from the matrix and not bounded yet: {', '.join(p.unbounded)} (a run stopped by "
              "--max-run-seconds into DIR/bounds/, as this script's help says).")


def main(dirs):
    parts = [Part(d) for d in dirs]
    check_parts(parts)
    _, scenes, solvers, _, _ = parts[0].study
    others = [s for s in solvers if s != HOT]
    owner = {sc: p for p in parts for sc in p.done}  # the part that holds each finished scene
    rows = [(sc, owner[sc]) for sc in scenes if sc in owner]
    several = len(parts) > 1

    def where(p):  # the machine column, when the table joins several parts
        return f" {p.machine or '?'} |" if several else ""

    print("# HOT supplement Table 1 at the paper's scale, like for like\n")
    build = (parts[0].commit or "?")[:7]
    if several:
        print(f"Build {build}, in {len(parts)} parts that ran on different machines. Each scene's runs "
              "all come from one machine, so every ratio below is measured on one machine; no summary "
              "pools two machines:\n")
        for p in parts:
            print(f"- {p.dir}: {p.machine or '?'}; scenes {', '.join(sc for sc in scenes if sc in p.present)}")
        print()
    else:
        print(f"Build {build}, every run on one machine ({parts[0].machine or '?'}).\n")
    for p in parts:
        if several:
            print(f"On {p.machine or '?'} ({p.dir}):\n")
        summary(p, solvers)
        if several:
            print()
    missing = [sc for sc in scenes if all(sc in p.missing for p in parts)]
    if missing:
        print(f"- Not run yet: {', '.join(missing)} (`matrix run` resumes).")

    print("\nHOT's speedup over each solver, total over the sampled frames (median of the runs; range "
          "over the runs in brackets) and the largest per-frame ratio of the sampled frames after the "
          "slash; `~` where the ranges overlap (within the noise):\n")
    print("| scene |" + (" machine |" if several else "") + " particles | frames timed | " + " | ".join(others) + " |")
    print("|---|" + ("---|" if several else "") + "---|---|" + "---|" * len(others))
    for sc, p in rows:
        timed, bounds = p.study[3], p.bounds
        h = timed[(sc, HOT)]
        frames = ", ".join(str(k) for k in sorted(h.timed))
        cols = []
        for so in others:
            if (sc, so) in bounds:
                b = bounds[(sc, so)]
                total, fr = bound_speedups(b, h)
                cols.append(f"≥ {mr.fmt(total)} / ≥ {mr.fmt(fr)} (bound{' busy' if b.busy else ''})")
                continue
            sp = mr.Speedup(h, timed[(sc, so)])
            cols.append("-" if sp.total is None else f"{sp.text()} / {mr.fmt(sp.per)}")
        print(f"| {sc} |{where(p)} {int(mr.number(h.row.get('particles'), 0)):,} | {frames} | " + " | ".join(cols) + " |")

    print("\nSeconds per sampled frame (median of the runs); iterations over the sampled frames in the first "
          "run, outer (Newton or L-BFGS) / linear (PN's PCG) / inner (inside the inverse approximation: "
          "the coarsest-level PCG of a geometric V-cycle, LBFGS-H's PCG; 0 where none is counted); "
          "peak resident memory in MB (the largest over the runs):\n")
    print("| scene |" + (" machine |" if several else "") + " " + " | ".join(solvers) + " |")
    print("|---|" + ("---|" if several else "") + "---|" * len(solvers))
    for sc, p in rows:
        timed, bounds = p.study[3], p.bounds
        cols = []
        for so in solvers:
            if (sc, so) in bounds:
                b = bounds[(sc, so)]
                o, li, inner = b.iters
                cols.append(f"≥ {mr.fmt(b.spent / len(timed[(sc, HOT)].timed))} (bound); ≥ {o} / {li} / {inner}")
                continue
            c = timed[(sc, so)]
            marks = "".join(f" {m}" for m in c.marks())
            its = f"{c.outer} / {c.linear} / {c.row.get('inner_iters') or '-'}"
            mb = max((mr.number(r.row.get("peak_rss_mb"), 0.0) for r in c.runs), default=0.0)
            cols.append(f"{mr.fmt(c.s_per_frame)}{marks}; {its}; {mb:.0f} MB")
        print(f"| {sc} |{where(p)} " + " | ".join(cols) + " |")

    print("\nHow far the sampled frames stand for the whole animation: each scene's reference run simulated "
          "every frame once (and wrote the checkpoints); its seconds per frame over all frames beside the "
          "same solver's median over the sampled frames:\n")
    print("| scene |" + (" machine |" if several else "") + " reference solver | frames | steps | whole animation, "
          "s/frame | slowest frame, s | sampled, s/frame | sampled / whole | peak MB |")
    print("|---|" + ("---|" if several else "") + "---|---|---|---|---|---|---|---|")
    for sc, p in rows:
        timed, refs = p.study[3], p.study[4]
        ref = refs.get(sc)
        if ref is None or (sc, ref.solver) not in timed:
            continue
        same = timed[(sc, ref.solver)]
        slowest = max(ref.frame_time.values()) if ref.frame_time else float("nan")
        whole = ref.s_per_frame
        busy = " busy" if ref.busy else ""
        other = p.other_build.get(sc)
        ratio = (f"- (reference: build {other[:7]})" if other
                 else mr.fmt(same.s_per_frame / whole if whole else float('nan')))
        print(f"| {sc} |{where(p)} {ref.solver} | {len(ref.frame_time)} | {ref.row.get('steps', '-')} | "
              f"{mr.fmt(whole)}{busy} | {mr.fmt(slowest)} | {mr.fmt(same.s_per_frame)} | {ratio} | "
              f"{mr.number(ref.row.get('peak_rss_mb'), 0.0):.0f} |")
    others = [(sc, p) for sc, p in rows if p.other_build.get(sc)]
    if others:
        print("\n" + "; ".join(f"{sc}'s reference ran on build {p.other_build[sc][:7]}, its cells on "
                               f"{(p.commit or '?')[:7]}" for sc, p in others)
              + ": its states are those the cells' build would reach (the page says how that was checked), "
              "and its times are not compared with the cells'.")
    bounded = [(sc, so, b, p) for p in parts for (sc, so), b in sorted(p.bounds.items())]
    if bounded:
        print("\nBounds: solvers a scene could not time three times, each run once from the same checkpoints "
              "and stopped by a time limit; seconds per sampled frame up to the stop (the last one cut short), "
              "against HOT's slowest run on the same frame:\n")
        print("| scene |" + (" machine |" if several else "") + " solver | stopped | seconds per frame | "
              "HOT's slowest, s |")
        print("|---|" + ("---|" if several else "") + "---|---|---|---|")
        for sc, so, b, p in bounded:
            hot = p.study[3][(sc, HOT)]
            secs = ", ".join(f"{k}: {mr.fmt(t)}" for k, t in sorted(b.frame_time.items()))
            slow = ", ".join(f"{k}: {mr.fmt(max(r.timed.get(k, float('nan')) for r in hot.runs))}"
                             for k in sorted(hot.timed))
            print(f"| {sc} |{where(p)} {so} | {b.text()} | {secs} | {slow} |")
    print()
    for p in parts:
        timed = p.study[3]
        runs = [r for c in timed.values() for r in c.runs]
        if not runs:
            continue
        print(f"{p.dir + ': ' if several else ''}{len(runs)} timed runs, {sum(r.busy for r in runs)} on a busy "
              f"machine, {sum(1 for r in runs if r.status != 'ok')} not ok; "
              f"median runs a cell {statistics.median(len(c.runs) for c in timed.values()):.0f}.")


def rerun_bounds(old, new, binary):
    """Runs every bound of the study OLD again into NEW/bounds/ with BINARY, the same way: the same
    scene, solver, eps, scale, threads, overrides, sampled frames and time limit, from the
    checkpoints of the same reference cell in NEW (whose id the same settings keep)."""
    for run_json in sorted(glob.glob(os.path.join(old, "bounds", "*", "run.json"))):
        try:
            with open(run_json) as f:
                r = json.load(f)
            ck = r["checkpoints"]
            ref = os.path.basename(os.path.dirname(ck["sample_from"].rstrip("/")))
            cmd = [binary, "run", "--scene", r["scene"], "--solver", r["solver"], "--eps", repr(r["eps"]),
                   "--scale", repr(r["scale"]), "--threads", str(r["threads"]),
                   "--sample-from", os.path.join(new, "cells", ref, "checkpoints"),
                   "--sample-frames", ck["sample_frames"], "--max-run-seconds", repr(r["limits"]["max_run_seconds"]),
                   "--out", os.path.join(new, "bounds", os.path.basename(os.path.dirname(run_json)))]
            cmd += [a for k, v in (r.get("overrides") or {}).items() for a in ("--set", f"{k}={v}")]
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
            mr.die(f"{run_json}: {e!r}")
        print("paper_scale_table.py: bound: " + " ".join(cmd), flush=True)
        if subprocess.run(cmd).returncode != 0:
            mr.die(f"{run_json}: its rerun failed", 1)


def write_table(out, dirs):
    """main(dirs) into the file out, which is replaced only when the whole table is made: a part that
    cannot join the others (another build or machine, a scene in two parts) leaves the old table."""
    part = out + ".part"
    try:
        with open(part, "w") as f, contextlib.redirect_stdout(f):
            main(dirs)
    except BaseException:
        if os.path.exists(part):
            os.remove(part)
        raise
    os.replace(part, out)


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--rerun-bounds":
        rerun_bounds(*sys.argv[2:])
    elif len(sys.argv) >= 4 and sys.argv[1] == "--out":
        write_table(sys.argv[2], sys.argv[3:])
    elif len(sys.argv) >= 2 and not sys.argv[1].startswith("-"):
        main(sys.argv[1:])
    else:
        print("usage: paper_scale_table.py RESULTS_DIR [RESULTS_DIR ...] | --out FILE RESULTS_DIR [...]"
              " | --rerun-bounds OLD_DIR NEW_DIR MPMBENCH", file=sys.stderr)
        sys.exit(2)
