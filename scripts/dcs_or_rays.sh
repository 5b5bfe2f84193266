#!/bin/bash
# The hybrid of DCS and shadow rays (`dcs-64-hybrid`) against DCS alone and the reference on
# the same scene, view and sample count: prepare + estimate seconds (best of $REPEATS runs each, default 5,
# release build), and what the hybrid chose. One markdown row per scene.
# usage: scripts/dcs_or_rays.sh WIDTH HEIGHT SCENE...
set -euo pipefail
W=$1; H=$2; shift 2
cargo build --release -q -p xtask
out=$(mktemp -d)
seconds() {
  python3 - "$out/stats.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
e = s["estimate"]
print(sum(p["seconds"] for p in e["phases"]) + sum(p["seconds"] for p in s["prepare"]["phases"]))
PY
}
echo "| scene | ${W}x${H} | dcs-64 (s) | ref-64 (s) | dcs-64-hybrid (s) | hybrid chose | hybrid / faster of the two |"
echo "|---|---|---|---|---|---|---|"
for sc in "$@"; do
  declare -A best=()
  for t in dcs-64 ref-64 dcs-64-hybrid; do
    b=1e9
    for _ in $(seq "${REPEATS:-5}"); do
      ./target/release/xtask render --scene "$sc" --technique "$t" --width "$W" --height "$H" --out "$out" >/dev/null 2>&1
      b=$(python3 -c "print(min($b, $(seconds)))")
    done
    best[$t]=$b
  done
  chose=$(python3 -c "import json; c=json.load(open('$out/stats.json'))['estimate']['counters']; print('rays' if c.get('squares-traced', 0) else 'dcs')")
  python3 -c "
d, r, h = ${best[dcs-64]}, ${best[ref-64]}, ${best[dcs-64-hybrid]}
print(f'| $sc | | {d:.4f} | {r:.4f} | {h:.4f} | $chose | {h / min(d, r):.2f}x |')"
done
rm -rf "$out"
