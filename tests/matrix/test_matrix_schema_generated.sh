#!/usr/bin/env bash
# docs/matrix.schema.json is generated: `mpmbench matrix schema` writes it
# from the run settings table (experiments/cli/run_settings.c) and the
# matrix file's own keys (experiments/matrix/matrix_keys.c). The committed
# copy, which scripts/check_matrices.py and test_matrix_schema validate
# against, must be that output byte for byte, so a table changed without
# regenerating the file fails here. `matrix --help` names the command, and
# docs/matrix-format.md names every key the schema has.
. "$(dirname "$0")/../common/shell_harness.sh"

"$bin" matrix schema >"$tmp/schema.json" 2>"$tmp/err"
check "matrix schema: exit 0, nothing on stderr" test $? -eq 0 -a ! -s "$tmp/err"
if ! cmp -s "$src/docs/matrix.schema.json" "$tmp/schema.json"; then
  echo "docs/matrix.schema.json differs from 'mpmbench matrix schema' (regenerate it:"
  echo "  mpmbench matrix schema > docs/matrix.schema.json):"
  diff "$src/docs/matrix.schema.json" "$tmp/schema.json" | head -20
fi
check "docs/matrix.schema.json is 'mpmbench matrix schema' byte for byte" cmp -s "$src/docs/matrix.schema.json" "$tmp/schema.json"
check "the schema is JSON" python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$tmp/schema.json"
check "docs/matrix-format.md names every key of the schema" python3 - "$tmp/schema.json" "$src/docs/matrix-format.md" <<'PY'
import json, sys
schema, doc = json.load(open(sys.argv[1])), open(sys.argv[2]).read()
parts = schema["$defs"]
keys = set(schema["properties"])
for part in (parts["defaults"], parts["scenes"]["additionalProperties"], parts["axes"], parts["reference"], parts["report"]):
    keys |= set(part["properties"])
missing = sorted(k for k in keys if "`%s`" % k not in doc and '"%s":' % k not in doc)  # a key, or one in an example
if missing:
    print("keys of the schema not in docs/matrix-format.md:", ", ".join(missing))
    sys.exit(1)
PY
"$bin" matrix --help >"$tmp/help" 2>&1
check "matrix --help names 'matrix schema'" grep -q "mpmbench matrix schema" "$tmp/help"
expect_input_error "matrix schema: unexpected argument 'x'" matrix schema x
finish
