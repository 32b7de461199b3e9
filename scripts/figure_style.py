"""The one figure style of mpmbench's reports (matrix_report.py and
matrix_report_accuracy.py): every figure gets a solver's colour, marker and
line style from here, so a solver looks the same in every figure of every
report.

Colours: the Okabe & Ito (2008) palette, made to stay distinct under the
common colour-vision deficiencies (protanopia, deuteranopia, tritanopia),
without its yellow (too light on white). Seven colours do not cover the 17
presets, so a solver is told apart by colour AND marker AND line style: the
presets of one family share a line style (PN: solid, L-BFGS: dashed, HOT:
dash-dot, Gast15 and the semi-implicit method: dotted), and no two presets
share a (colour, marker) pair. A variant written "preset:key=value" keeps
its preset's colour and gets the next marker of a second sequence, so the
tau sweep of Gast15 reads as one family. Unknown names get a colour and
marker from a hash of the name (stable across reports).

Sizes: a single-column figure is 3.5 x 2.6 inches, a two-panel one the width
of two columns (7.1 inches), both at 8-point type; PNG at 200 dpi (700 x 520
pixels for one column) and SVG beside it.
"""
import zlib

# Okabe-Ito without yellow, ordered so the first presets get the strongest contrasts
OKABE_ITO = {
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "bluish green": "#009E73",
    "reddish purple": "#CC79A7",
    "orange": "#E69F00",
    "sky blue": "#56B4E9",
    "black": "#000000",
}
_C = list(OKABE_ITO.values())

# preset -> (colour index, marker, line style); (colour, marker) pairs are unique
PRESETS = {
    "pn-pcg": (6, "o", "-"),            # the baseline of most studies: black circles
    "pn-pcg-mf": (0, "o", "-"),
    "pn-pcg-scalar": (5, "o", "-"),
    "pn-sgs-pcg": (3, "o", "-"),
    "pn-mgpcg": (2, "s", "-"),
    "pn-gmgpcg": (4, "s", "-"),
    "pn-amg-pcg": (5, "s", "-"),
    "pn-cholmod": (3, "s", "-"),
    "hot": (1, "D", "-."),
    "hot-quadratic": (4, "D", "-."),
    "lbfgs-h": (2, "^", "--"),
    "lbfgs-h-direct": (0, "^", "--"),
    "lbfgs-gmg": (3, "^", "--"),
    "lbfgs-amg": (5, "^", "--"),
    "gast15": (0, "v", ":"),
    "gast15-hot": (1, "v", ":"),
    "semi-implicit": (6, "P", ":"),
}
VARIANT_MARKERS = ["X", "*", "p", "h", "<", ">", "d", "8"]
OTHER_MARKERS = ["o", "s", "D", "^", "v", "P", "X", "*"]

FONT_PT = 8
ONE_COLUMN = (3.5, 2.6)
TWO_COLUMNS = (7.1, 2.8)
DPI = 200

# status words of the robustness grid and their cell colours (light, so the word stays readable)
STATUS_FILL = {"pass": "#CCE5F0", "FAIL": "#F5CCB3", "-": "#FFFFFF"}


def solver_style(name, variants=None):
    """(colour, marker, line style) of a solver name; variants: the ordered list of
    the variant names in the figure (for 'preset:opts' names)."""
    base, _, opts = name.partition(":")
    if base in PRESETS:
        ci, marker, ls = PRESETS[base]
        if opts:
            k = (variants or [name]).index(name) if variants and name in variants else zlib.crc32(name.encode()) % 8
            marker = VARIANT_MARKERS[k % len(VARIANT_MARKERS)]
        return _C[ci], marker, ls
    h = zlib.crc32(name.encode())
    return _C[h % len(_C)], OTHER_MARKERS[(h // 7) % len(OTHER_MARKERS)], "-"


SHORT_LABEL = 26  # characters a solver's label may take in a figure (the tables keep the whole spec)


def short_name(name):
    """A solver's label in figures: the name itself when short; else the spec's
    head (preset or OUTER:INVERSE), its first option and how many more, so
    that 'pn:petsc:pc_type=hypre,pc_hypre_...,reuse_every=0' reads
    'pn:petsc:pc_type=hypre +3'. The tables name the whole spec."""
    if len(name) <= SHORT_LABEL:
        return name
    parts = name.split(":")
    head = ":".join(parts[:-1]) if len(parts) > 1 else ""
    opts = parts[-1].split(",") if len(parts) > 1 else [name]
    label = (head + ":" if head else "") + opts[0] + (f" +{len(opts) - 1}" if len(opts) > 1 else "")
    return label if len(label) <= SHORT_LABEL + 8 else label[:SHORT_LABEL + 5] + "..."


def line_kwargs(name, names=None, ms=4.0, lw=1.2):
    """Keyword arguments of ax.plot for a solver (names: every solver of the figure)."""
    variants = [n for n in (names or []) if ":" in n]
    colour, marker, ls = solver_style(name, variants)
    return {"color": colour, "marker": marker, "linestyle": ls, "markersize": ms, "linewidth": lw,
            "label": short_name(name),
            "markerfacecolor": "none" if ":" in name else colour}


def apply(matplotlib):
    """The rcParams of every report figure."""
    matplotlib.rcParams.update({
        "font.size": FONT_PT, "axes.titlesize": FONT_PT + 1, "axes.labelsize": FONT_PT,
        "xtick.labelsize": FONT_PT - 1, "ytick.labelsize": FONT_PT - 1, "legend.fontsize": FONT_PT - 1,
        "legend.frameon": False, "axes.spines.top": False, "axes.spines.right": False,
        "axes.grid": True, "grid.alpha": 0.3, "grid.linewidth": 0.5, "lines.linewidth": 1.2,
        "savefig.dpi": DPI, "figure.dpi": DPI, "svg.fonttype": "none", "figure.constrained_layout.use": True,
        "svg.hashsalt": "mpmbench",  # the same SVG for the same data (no random ids)
    })
