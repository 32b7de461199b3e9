#!/usr/bin/env bash
# `run --vtk DIR [--vtk-grid]`: the ParaView time series read back with
# VTK's own XML reader (Debian's python3-vtk9, installed by scripts/test.sh):
# particles.pvd lists frames 0..N at the simulated times of steps.csv; each
# .vtp has every particle (the count of steps.csv) as a point and a vertex
# cell; positions, velocities and materials equal the PLY of the same run
# (--particles, float32 both), id is a permutation, J lies in the range the
# initial F allows at frame 0, von Mises is positive where F is not a
# rotation, plastic_J is 1 for an elastic material; grid.pvd has frames
# 1..N; with --vtk-grid-min-mass 0 every node is written and the nodal
# masses add up to the particles' mass (P2G conserves it); by default the
# nodes under 1e-3 of the heaviest are left out (this scene has some, with
# velocities far above any particle's), the rest are those of the full file.
. "$(dirname "$0")/../common/shell_harness.sh"
py=${MPM_PYTHON:-/usr/bin/python3}
"$py" -c "import vtk" 2>/dev/null || skip "$py has no vtk module (Debian: python3-vtk9; scripts/test.sh installs it)"
"$bin" run --scene stretched-box --solver pn-pcg --scale 5 --frames 2 --quiet --out "$tmp/run" \
  --set objects.0.initial_F.per_particle=true --particles "$tmp/ply" --vtk "$tmp/vtk" --vtk-grid 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "run --vtk exit 0 ($(head -c 200 "$tmp/err"))" test $rc -eq 0
"$bin" run --scene stretched-box --solver pn-pcg --scale 5 --frames 2 --quiet --out "$tmp/run0" \
  --set objects.0.initial_F.per_particle=true --vtk "$tmp/vtk0" --vtk-grid --vtk-grid-min-mass 0 2>"$tmp/err0"
rc=$?  # before the description's $(...), which resets $?
check "run --vtk-grid-min-mass 0: exit 0 ($(head -c 200 "$tmp/err0"))" test $rc -eq 0
check "the files" test -s "$tmp/vtk/particles.pvd" -a -s "$tmp/vtk/particles_0000.vtp" -a -s "$tmp/vtk/particles_0002.vtp" \
  -a -s "$tmp/vtk/grid.pvd" -a -s "$tmp/vtk/grid_0001.vtp" -a ! -e "$tmp/vtk/grid_0000.vtp"
"$py" - "$tmp" >"$tmp/check.txt" 2>&1 <<'PY'
import csv, struct, sys
import xml.etree.ElementTree as ET
import vtk
from vtk.util.numpy_support import vtk_to_numpy
import numpy as np

tmp = sys.argv[1]
fails = []
def want(cond, what):
    if not cond:
        fails.append(what)

def read(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    out = r.GetOutput()
    pd = out.GetPointData()
    arrays = {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}
    return out, vtk_to_numpy(out.GetPoints().GetData()), arrays

steps = list(csv.DictReader(open(f"{tmp}/run/steps.csv")))
n = int(steps[-1]["particles"])
ends = {}
for s in steps:  # the time at each frame's end
    ends[int(s["frame"]) + 1] = float(s["t"]) + float(s["dt"])
ends[0] = 0.0
sets = ET.parse(f"{tmp}/vtk/particles.pvd").getroot().findall("./Collection/DataSet")
want([d.get("file") for d in sets] == [f"particles_{k:04d}.vtp" for k in range(3)], f"pvd files {[d.get('file') for d in sets]}")
want(all(abs(float(d.get("timestep")) - ends[k]) < 1e-12 for k, d in enumerate(sets)), "pvd times = steps.csv frame ends")

def ply(path):
    data = open(path, "rb").read()
    body = data[data.index(b"end_header\n") + len(b"end_header\n"):]
    rec = np.frombuffer(body, dtype=np.dtype([("x", "<f4", 3), ("v", "<f4", 3), ("m", "<i4")]))
    return rec

for k in range(3):
    out, x, a = read(f"{tmp}/vtk/particles_{k:04d}.vtp")
    want(out.GetNumberOfPoints() == n and out.GetNumberOfVerts() == n, f"frame {k}: {out.GetNumberOfPoints()} points, {n} particles")
    want(set(a) == {"velocity", "material", "id", "J", "plastic_J", "von_mises", "mass", "volume"}, f"arrays {sorted(a)}")
    want(sorted(a["id"].tolist()) == list(range(n)), f"frame {k}: id a permutation")
    if k:
        p = ply(f"{tmp}/ply/frame_{k:04d}.ply")
        want(np.array_equal(p["x"], x), f"frame {k}: positions equal the PLY's")
        want(np.array_equal(p["v"], a["velocity"]), f"frame {k}: velocities equal the PLY's")
        want(np.array_equal(p["m"], a["material"]), f"frame {k}: materials equal the PLY's")
    want(np.all(a["plastic_J"] == 1.0), f"frame {k}: plastic_J 1 (elastic)")
    want(np.all(a["von_mises"] > 0) and np.all(np.isfinite(a["von_mises"])), f"frame {k}: von Mises > 0")
    if k == 0:
        want(np.all(a["J"] >= 0.7 ** 3 * (1 - 1e-6)) and np.all(a["J"] <= 1.3 ** 3 * (1 + 1e-6)), "frame 0: J of diag F in [0.7, 1.3]^3")
        want(np.std(a["J"]) > 0.01, "frame 0: J per particle")
        want(np.all(a["velocity"] == 0), "frame 0: at rest")
        mass = float(np.sum(a["mass"], dtype=np.float64))
gsets = ET.parse(f"{tmp}/vtk/grid.pvd").getroot().findall("./Collection/DataSet")
want([d.get("file") for d in gsets] == ["grid_0001.vtp", "grid_0002.vtp"], "grid pvd: frames 1 and 2")
for k in (1, 2):
    out0, x0, a0 = read(f"{tmp}/vtk0/grid_{k:04d}.vtp")
    gm = float(np.sum(a0["mass"], dtype=np.float64))
    want(abs(gm - mass) <= 1e-5 * mass, f"grid {k} (every node): nodal mass {gm} = particle mass {mass}")
    want(np.allclose(a0["momentum"], a0["mass"][:, None] * a0["velocity"], rtol=1e-5, atol=1e-12), "momentum = mass x velocity")
    out, x, a = read(f"{tmp}/vtk/grid_{k:04d}.vtp")
    light = a0["mass"] < 1e-3 * a0["mass"].max()
    want(light.any(), f"grid {k}: the scene has nodes under 1e-3 of the heaviest")
    want(out.GetNumberOfPoints() == out0.GetNumberOfPoints() - int(light.sum()),
         f"grid {k}: the default leaves out exactly those ({out.GetNumberOfPoints()} of {out0.GetNumberOfPoints()}, {int(light.sum())} light)")
    want(np.all(a["mass"] >= 1e-3 * a0["mass"].max()), f"grid {k}: no light node kept")
    want(np.array_equal(x, x0[~light]) and np.array_equal(a["velocity"], a0["velocity"][~light]),
         f"grid {k}: the kept nodes are the full file's, in order")
    want(a["velocity"].shape == (out.GetNumberOfPoints(), 3), "grid velocity: 3 per node")
    want(np.allclose(x / 0.05, np.round(x / 0.05), atol=1e-4), "grid nodes at multiples of dx")
print("ok" if not fails else "; ".join(fails))
PY
check "read back with VTK ($(head -c 600 "$tmp/check.txt"))" grep -qx ok "$tmp/check.txt"
expect_input_error "--vtk-grid-min-mass 0.5: needs --vtk-grid" run --scene drop --solver pn-pcg --frames 1 --quiet --out "$tmp/x" --vtk "$tmp/y" --vtk-grid-min-mass 0.5
expect_input_error "--vtk-grid-min-mass '2'" run --scene drop --solver pn-pcg --frames 1 --quiet --out "$tmp/x" --vtk "$tmp/y" --vtk-grid --vtk-grid-min-mass 2
expect_input_error "--vtk-grid: needs --vtk DIR" run --scene drop --solver pn-pcg --frames 1 --quiet --out "$tmp/x" --vtk-grid
finish
