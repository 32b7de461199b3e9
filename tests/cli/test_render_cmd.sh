#!/usr/bin/env bash
# `mpmbench render`: pictures of the initial state of drop and bar3 (coarse)
# are PNG files of a sane size, options shape the image, and bad input gives
# exit status 2 with one line that names the problem.
. "$(dirname "$0")/../common/shell_harness.sh"
export MPM_SCENE_DIR="$src/experiments/scenes"

# png_size FILE: prints "W H" from the IHDR chunk, nothing if not a PNG
png_size() {
  python3 - "$1" <<'PY'
import struct, sys
try:
    with open(sys.argv[1], "rb") as f:
        head = f.read(24)
except OSError:
    sys.exit(0)
if len(head) == 24 and head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
    print(*struct.unpack(">II", head[16:24]))
PY
}

# png_ok FILE MIN MAX: a PNG whose sides are within [MIN, MAX]
png_ok() {
  local wh
  wh=$(png_size "$1")
  [ -n "$wh" ] || { echo "  $1: not a PNG"; return 1; }
  set -- $wh "$2" "$3"
  [ "$1" -ge "$3" ] && [ "$1" -le "$4" ] && [ "$2" -ge "$3" ] && [ "$2" -le "$4" ] \
    || { echo "  size ${1}x$2 outside [$3, $4]"; return 1; }
}

# png_is FILE W H
png_is() { [ "$(png_size "$1")" = "$2 $3" ] || { echo "  $1: $(png_size "$1"), wanted $2 $3"; return 1; }; }


# frame 0 of drop, default name <scene>.png in the working directory
(cd "$tmp" && "$bin" render --scene drop --scale 4 >"$tmp/drop.out" 2>"$tmp/drop.err")
rc=$?  # before the description's $(...), which resets $?
check "render drop exit 0 ($(cat "$tmp/drop.err"))" test $rc -eq 0
check "drop.png written in the working directory" png_ok "$tmp/drop.png" 100 2000
check "render prints the file it wrote" grep -q "drop.png" "$tmp/drop.out"

# bar3, explicit output, views and colouring
"$bin" render --scene bar3 --scale 4 --out "$tmp/bar3.png" >/dev/null 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "render bar3 exit 0 ($(cat "$tmp/err"))" test $rc -eq 0
check "bar3.png is a sane PNG" png_ok "$tmp/bar3.png" 100 2000
wh=$(png_size "$tmp/bar3.png")
check "bar3 front view is taller than wide ($wh)" test "${wh#* }" -gt "${wh% *}"
"$bin" render --scene bar3 --scale 4 --view iso --color speed --width 320 --height 240 --out "$tmp/iso.png" >/dev/null 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "render bar3 iso exit 0 ($(cat "$tmp/err"))" test $rc -eq 0
check "--width/--height give the image size" png_is "$tmp/iso.png" 320 240
"$bin" render --scene drop --scale 4 --view top --width 300 --out "$tmp/top.png" --set materials.soft.E=2e5 >/dev/null 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "render with --width only and --set exit 0 ($(cat "$tmp/err"))" test $rc -eq 0
wh=$(png_size "$tmp/top.png")
check "--width alone sets the width ($wh)" test "${wh% *}" = 300
"$bin" render --scene "$src/experiments/scenes/drop.json" --scale 4 --view side --out "$tmp/file.png" >/dev/null 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "render a scene file exit 0 ($(cat "$tmp/err"))" test $rc -eq 0
check "scene file picture" png_ok "$tmp/file.png" 100 2000

# frame 1: simulated with a solver, then drawn
"$bin" render --scene drop --scale 4 --frame 1 --solver pn-pcg-mf --threads 1 --out "$tmp/f1.png" >"$tmp/f1.out" 2>"$tmp/err"
rc=$?  # before the description's $(...), which resets $?
check "render frame 1 exit 0 ($(cat "$tmp/err"))" test $rc -eq 0
check "frame 1 picture" png_ok "$tmp/f1.png" 100 2000
check "frame 1 is at t = 1/24 s" grep -q "t = 0.04167 s" "$tmp/f1.out"

# bad usage and bad input
expect_input_error "--view 'sideways'" render --scene drop --view sideways --out "$tmp/x.png"
expect_input_error "--color 'stress'" render --scene drop --color stress --out "$tmp/x.png"
expect_input_error "--frame" render --scene drop --frame -1 --out "$tmp/x.png"
expect_input_error "--frame" render --scene drop --frame two --out "$tmp/x.png"
expect_input_error "--width" render --scene drop --width 0 --out "$tmp/x.png"
expect_input_error "--scale" render --scene drop --scale -2 --out "$tmp/x.png"
expect_input_error "--scene is required" render --frame 0
expect_input_error "unknown option" render --scene drop --bogus 1
expect_input_error "missing value" render --scene drop --view
expect_input_error "unknown solver 'nosuch'" render --scene drop --solver nosuch --out "$tmp/x.png"
expect_input_error "nosuchscene" render --scene nosuchscene --out "$tmp/x.png"
expect_input_error "materials.soft.E|E.*-5" render --scene drop --set materials.soft.E=-5 --out "$tmp/x.png"
expect_input_error "no_such_dir" render --scene drop --scale 4 --out "$tmp/no_such_dir/x.png"
check "no picture from bad input" test ! -e "$tmp/x.png"

finish
