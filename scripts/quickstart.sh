#!/usr/bin/env bash
# Runs the README's quickstart as written and checks the report it ends with, so that CI fails
# when the README's commands stop working.
#
# The shell block is read from README.md at run time: the first ```sh block under
# "## Quickstart". It runs with `bash -euo pipefail` in a fresh folder holding a copy of the
# repository's tracked files, whose `target` is a link to this checkout's build folder (the
# block starts after the README's build step, and nothing is rebuilt). Then the report's
# metrics.json must hold the trained model and the classical baseline, and the model's MSE
# must be below the baseline's.
#
# Use: scripts/quickstart.sh   (after cargo build --release --workspace; KEEP=1 keeps the folder)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
target=${CARGO_TARGET_DIR:-$repo/target}
for bin in lfgen lftrain lfeval; do
    [ -x "$target/release/$bin" ] || {
        echo "quickstart: $target/release/$bin is missing: run cargo build --release --workspace" >&2
        exit 1
    }
done

# The first ```sh block after the "## Quickstart" heading and before the next "## " heading.
block=$(awk '
    /^## / { inside = ($0 == "## Quickstart") }
    inside && !code && /^```sh$/ { code = 1; next }
    code && /^```$/ { exit }
    code { print }
' "$repo/README.md")
[ -n "$block" ] || {
    echo "quickstart: README.md has no \`\`\`sh block under \"## Quickstart\"" >&2
    exit 1
}

work=$(mktemp -d "${TMPDIR:-/tmp}/lfgen-quickstart.XXXXXX")
[ -n "${KEEP:-}" ] || trap 'rm -rf "$work"' EXIT
git -C "$repo" ls-files -z | (cd "$repo" && tar --null --ignore-failed-read -T - -cf -) | tar -C "$work" -xf -
ln -s "$target" "$work/target"

echo "quickstart: running README.md's block in $work"
start=$SECONDS
(cd "$work" && CARGO_TARGET_DIR="$target" bash -euo pipefail -c "$block")
echo "quickstart: the block ran in $((SECONDS - start)) s"

# The report is the last --out folder of an lfeval evaluation in the block.
report=$(grep -o 'lfeval [^|;&]*--out [^ ]*' <<<"$block" | grep -v ' baseline \| truth ' |
    tail -1 | sed 's/.*--out //')
metrics="$work/$report/metrics.json"
[ -f "$metrics" ] || {
    echo "quickstart: the block wrote no report at $report/metrics.json" >&2
    exit 1
}
python3 - "$metrics" <<'EOF'
import json, sys

path = sys.argv[1]
methods = {m["name"]: m["summary"] for m in json.load(open(path))["methods"]}
baseline = [n for n in methods if "baseline" in n]
models = [n for n in methods if "baseline" not in n]
if not baseline or not models:
    sys.exit(f"quickstart: {path} needs a trained model and the baseline, has {sorted(methods)}")

def mse(name):
    value = methods[name]["unimodal"]["front"]["mse_x100"]
    if value is None:
        sys.exit(f"quickstart: {path} has no MSE for {name}")
    return value

for model in models:
    print(f"quickstart: {model} MSE×100 {mse(model):.2f}, {baseline[0]} {mse(baseline[0]):.2f}")
    if not mse(model) < mse(baseline[0]):
        sys.exit(f"quickstart: {model} does not beat the classical baseline's MSE ({path})")
EOF
