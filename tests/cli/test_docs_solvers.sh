#!/usr/bin/env bash
# docs/solvers.md documents every solver: each preset of `mpmbench list
# solvers` with its composition, each registered outer method, inverse
# approximation, line search and stopping rule, and every option key a part
# reads (solver_opt_* calls in solvers/ and adapters/).
. "$(dirname "$0")/../common/shell_harness.sh"
doc="$src/docs/solvers.md"
"$bin" list solvers >"$tmp/list" 2>&1
check "list solvers" test -s "$tmp/list"

documented() { grep -qF -- "$1" "$doc"; }
# presets: "name  description  [outer:inverse(:options)]"
while read -r name rest; do
  comp=$(printf '%s\n' "$rest" | sed -n 's/.*\[\(.*\)\]$/\1/p')
  check "preset $name is a table row" documented "| \`$name\` |"
  check "preset $name's composition $comp is documented" documented "\`$comp\`"
done < <(awk '/^$/{exit} {print}' "$tmp/list")
# parts and strategies: the indented names of each section
for part in $(awk '/^(outer methods|inverse approximations|line searches|stopping rules)/{on=1; next} /^$/{on=0} on{print $1}' "$tmp/list"); do
  check "part $part is documented" documented "\`$part\`"
done
# option keys read by the parts
keys=$(grep -rhoE 'solver_opt_(int|number|string)\([^,]+, *"[a-z_0-9]+"' "$src/solvers" "$src/adapters" \
       | sed -E 's/.*"([a-z_0-9]+)"$/\1/' | sort -u)
check "option keys found in the sources" test -n "$keys"
for k in $keys; do
  check "option $k is documented" documented "\`$k\`"
done
finish
