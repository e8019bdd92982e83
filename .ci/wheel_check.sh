#!/usr/bin/env bash
# The wheel on its own: build it, install it (not editable) into a fresh venv, and run the twin
# from a folder outside the checkout, so nothing can be read from the source tree.
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 -m venv "$work/build-venv"
"$work/build-venv/bin/pip" install -q build
"$work/build-venv/bin/python" -m build --wheel --outdir "$work/dist" . >/dev/null
wheel=$(ls "$work"/dist/*.whl)
echo "wheel: $(basename "$wheel")"
listing=$(python3 -m zipfile -l "$wheel")
for needed in models/joint.xml twin/plants/data/as_built.json twin/experiments/data/t3_prediction.csv viz/live_page.html viz/recording_page.html viz/strip_chart.js; do
  grep -q "^$needed " <<<"$listing" || { echo "wheel check: $needed is missing from the wheel" >&2; exit 1; }
done
python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q "$wheel"
mkdir "$work/elsewhere" && cd "$work/elsewhere"
"$work/venv/bin/twin" demo --no-plots --seeds 1 --out demo
"$work/venv/bin/twin" run --controller smc --trajectory 3 --plant as-built --payload 6.5 --orientation vertical --json
test -f demo/results.csv
echo "wheel check: passed"
