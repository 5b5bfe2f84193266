#!/usr/bin/env bash
# Instructions (and, with --cache, simulated cache misses) of one estimate on one thread, from
# `valgrind --tool=callgrind`: the `dcs_estimates` example run with one estimate minus the same
# run with none, so that loading the scene, rendering the view samples and `prepare` cancel.
# Counts do not drift with the machine's other load, unlike wall time, so they judge changes of
# a few percent that wall time on a shared machine cannot:
#
#     scripts/dcs_instructions.sh [--cache] [SCENE] [TECHNIQUE] [SIZE]
#
# TECHNIQUE is a DCS preset (default `dcs-64`), `reference`, `stratified-N` / `reference-N`
# (the `dcs-64` configuration at N samples and the reference on its samples), or
# `interleaved-N` / `reference-interleaved-N` (the same with 4 x 4 interleaved sets). The cache model
# is a 48 KiB, 12-way L1 and a 4 MiB, 16-way last level (the documented machine's L1 and L2).
# Needs valgrind (`apt-get install -y valgrind`); builds the example first. The callgrind
# files are left in ${CG_OUT:-/tmp} as dcs_cg_1.out and dcs_cg_0.out for `callgrind_annotate`;
# `python3 scripts/dcs_profile.py [--inclusive]` lists the estimate's instructions by function.
# `DCS_LIGHT_SCALE=K` in the environment reaches the example: the scene's rectangle light scaled.
set -euo pipefail
cache=()
if [[ ${1:-} == --cache ]]; then
  cache=(--cache-sim=yes --D1=49152,12,64 --LL=4194304,16,64)
  shift
fi
scene=${1:-bunny} technique=${2:-dcs-64} size=${3:-512}
out=${CG_OUT:-/tmp}
cd "$(dirname "$0")/.."
cargo build --release -q -p shadow-dcs --example dcs_estimates
bin=${CARGO_TARGET_DIR:-target}/release/examples/dcs_estimates
# The "Collected" line: Ir, then with the cache model D1mr D1mw ... (see callgrind's header).
collect() {
  local log
  log=$(RAYON_NUM_THREADS=1 valgrind --tool=callgrind --error-exitcode=0 "${cache[@]}" \
    --callgrind-out-file="$out/dcs_cg_$1.out" "$bin" "$scene" "$size" "$technique" "$1" 2>&1) || {
    echo "$log" >&2
    exit 1
  }
  grep "Collected" <<<"$log" | sed 's/.*Collected : //'
}
one=$(collect 1)
none=$(collect 0)
if ((${#cache[@]})); then
  # Events: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw.
  read -r i1 _ _ _ r1 w1 _ lr1 lw1 <<<"$one"
  read -r i0 _ _ _ r0 w0 _ lr0 lw0 <<<"$none"
  echo "$technique $scene ${size}x$size: $(((i1 - i0) / 1000000)) M instructions," \
    "L1 data misses $(((r1 + w1 - r0 - w0) / 1000)) k, last-level misses $(((lr1 + lw1 - lr0 - lw0) / 1000)) k"
else
  read -r i1 _ <<<"$one"
  read -r i0 _ <<<"$none"
  echo "$technique $scene ${size}x$size: $(((i1 - i0) / 1000000)) M instructions"
fi
