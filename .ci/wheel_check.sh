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
for needed in models/joint.xml twin/plants/data/as_built.json twin/experiments/data/t3_prediction.csv twin/experiments/data/t3_prediction_members.csv viz/live_page.html viz/recording_page.html viz/strip_chart.js; do
  grep -q "^$needed " <<<"$listing" || { echo "wheel check: $needed is missing from the wheel" >&2; exit 1; }
done
python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q "$wheel"
mkdir "$work/elsewhere" && cd "$work/elsewhere"
"$work/venv/bin/twin" demo --no-plots --seeds 1 --out demo
"$work/venv/bin/twin" run --controller smc --trajectory 3 --plant as-built --payload 6.5 --orientation vertical --json
test -f demo/results.csv
# The committed T3 prediction is package data: score made-up measurements (not a guess of T3) against it.
{ echo "controller,payload_g,orientation,rmse_mean_deg,rmse_std_deg"
  for c in ffpva smc; do for o in horizontal vertical; do for g in 0 6.5 13.5; do echo "$c,$g,$o,2.5,0.2"; done; done; done
} > made_up_t3.csv
"$work/venv/bin/twin" score --measured made_up_t3.csv --out score
test -f score/score.md
echo "wheel check: passed"
