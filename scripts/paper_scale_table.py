#!/usr/bin/env python3
"""HOT's supplement Table 1 at the paper's particle counts, from a finished
run of experiments/matrices/paper-scale.json:

    python3 scripts/paper_scale_table.py results/paper-scale > results/paper-scale/table.md

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
"""
import os
import statistics
import sys

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


def main(d):
    study = load(d)
    _, scenes, solvers, timed, refs = study
    others = [s for s in solvers if s != HOT]
    speed = hot_speedups(study)
    paper_set = [so for so in solvers if so == HOT or so in PAPER_TOTAL]
    wins = fastest(study, paper_set)
    done = [sc for sc in scenes if all((sc, so) in timed for so in solvers)]
    missing = [sc for sc in scenes if sc not in done]

    print("# HOT supplement Table 1 at the paper's scale, like for like\n")
    ranked = [sc for sc in done if wins.get(sc)]
    alone = [sc for sc in ranked if wins[sc] == [HOT]]
    tied = [sc for sc in ranked if HOT in wins[sc] and len(wins[sc]) > 1]
    lost = [sc for sc in ranked if HOT not in wins[sc]]
    print(f"- Among the paper's solvers ({', '.join(paper_set)}) HOT was the fastest on {len(alone)} of "
          f"{len(ranked)} scenes "
          f"by more than the spread of the runs, tied for the fastest on {len(tied)}"
          + (f" ({', '.join(tied)})" if tied else "")
          + (f"; slower on {', '.join(f'{sc} (fastest: {wins[sc][0]})' for sc in lost)}" if lost else "")
          + ". The paper: HOT the fastest of these on all but two of its ten scenes.")
    for so in others:
        sp = speed.get(so, {})
        if not sp:
            continue
        tot = [s.total for s in sp.values()]
        per = [s.per for s in sp.values() if s.per]
        paper = f"; the paper: {PAPER_TOTAL[so]}x" if so in PAPER_TOTAL else "; the paper has no such solver"
        print(f"- HOT against {so}: {mr.geomean(tot):.2f}x as fast in total (geometric mean over {len(tot)} scenes, "
              f"{span(tot)}x), largest per-frame ratio {span(per)}x{paper}.")
    if missing:
        print(f"- Not run yet: {', '.join(missing)} (`matrix run` resumes).")

    print("\nHOT's speedup over each solver, total over the sampled frames (median of the runs; range "
          "over the runs in brackets) and the largest per-frame ratio of the sampled frames after the "
          "slash; `~` where the ranges overlap (within the noise):\n")
    print("| scene | particles | frames timed | " + " | ".join(others) + " |")
    print("|---|---|---|" + "---|" * len(others))
    for sc in done:
        h = timed[(sc, HOT)]
        frames = ", ".join(str(k) for k in sorted(h.timed))
        cols = []
        for so in others:
            sp = mr.Speedup(h, timed[(sc, so)])
            cols.append("-" if sp.total is None else f"{sp.text()} / {mr.fmt(sp.per)}")
        print(f"| {sc} | {int(mr.number(h.row.get('particles'), 0)):,} | {frames} | " + " | ".join(cols) + " |")

    print("\nSeconds per sampled frame (median of the runs); iterations over the sampled frames in the first "
          "run, outer (Newton or L-BFGS) / linear (PN's PCG) / inner (inside the inverse approximation: "
          "the coarsest-level PCG of a geometric V-cycle, LBFGS-H's PCG; 0 where none is counted); "
          "peak resident memory in MB (the largest over the runs):\n")
    print("| scene | " + " | ".join(solvers) + " |")
    print("|---|" + "---|" * len(solvers))
    for sc in done:
        cols = []
        for so in solvers:
            c = timed[(sc, so)]
            marks = "".join(f" {m}" for m in c.marks())
            its = f"{c.outer} / {c.linear} / {c.row.get('inner_iters') or '-'}"
            mb = max((mr.number(r.row.get("peak_rss_mb"), 0.0) for r in c.runs), default=0.0)
            cols.append(f"{mr.fmt(c.s_per_frame)}{marks}; {its}; {mb:.0f} MB")
        print(f"| {sc} | " + " | ".join(cols) + " |")

    print("\nHow far the sampled frames stand for the whole animation: each scene's reference run simulated "
          "every frame once (and wrote the checkpoints); its seconds per frame over all frames beside the "
          "same solver's median over the sampled frames:\n")
    print("| scene | reference solver | frames | steps | whole animation, s/frame | slowest frame, s | "
          "sampled, s/frame | sampled / whole | peak MB |")
    print("|---|---|---|---|---|---|---|---|---|")
    for sc in done:
        ref = refs.get(sc)
        if ref is None or (sc, ref.solver) not in timed:
            continue
        same = timed[(sc, ref.solver)]
        slowest = max(ref.frame_time.values()) if ref.frame_time else float("nan")
        whole = ref.s_per_frame
        busy = " busy" if ref.busy else ""
        print(f"| {sc} | {ref.solver} | {len(ref.frame_time)} | {ref.row.get('steps', '-')} | {mr.fmt(whole)}{busy} | "
              f"{mr.fmt(slowest)} | {mr.fmt(same.s_per_frame)} | "
              f"{mr.fmt(same.s_per_frame / whole if whole else float('nan'))} | "
              f"{mr.number(ref.row.get('peak_rss_mb'), 0.0):.0f} |")
    runs = [r for c in timed.values() for r in c.runs]
    print(f"\n{len(runs)} timed runs, {sum(r.busy for r in runs)} on a busy machine, "
          f"{sum(1 for r in runs if r.status != 'ok')} not ok; "
          f"median runs a cell {statistics.median(len(c.runs) for c in timed.values()):.0f}.")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: paper_scale_table.py RESULTS_DIR", file=sys.stderr)
        sys.exit(2)
    main(sys.argv[1])
