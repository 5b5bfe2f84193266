#!/usr/bin/env bash
# AFSM against the CPU reference on the same samples, one row per built-in scene AFSM's soft
# shadows take (docs/benchmarks.md): scripts/afsm_table.sh [N] [mode] [width] [height].
set -euo pipefail
n=${1:-128}
mode=${2:-exact}
w=${3:-128}
h=${4:-96}
cargo build -q --release -p shadow-afsm --example afsm_bench
echo "| scene | AFSM s | reference s | AFSM / reference | pairs tested | empty | tiles culled | pairs after umbra |"
echo "|---|---|---|---|---|---|---|---|"
for s in quad-over-plane overlapping-occluders large-light-close bunny spot-self-shadow grass \
    contact semi-opaque textured-light sphere-light cornell-box spot-lamp interior interior-window; do
    target/release/examples/afsm_bench "$s" "$w" "$h" "$n" "$mode" 2>/dev/null | tail -1
done
