#!/usr/bin/env bash
# Runs two builds of the shadow-dcs `dcs_bench` example alternately, so that both see the same
# machine drift, and prints each run and the means:
#
#     scripts/dcs_ab.sh OLD_BINARY NEW_BINARY [ROUNDS] [SCENE] [SIZE] [SAMPLES]
#
# Build a binary with `cargo build --release -p shadow-dcs --example dcs_bench` and copy
# `target/release/examples/dcs_bench` away before building the other (a `git worktree` for an
# older commit, with its own CARGO_TARGET_DIR, keeps both).
set -euo pipefail
a=$1 b=$2 rounds=${3:-3} scene=${4:-bunny} size=${5:-512} samples=${6:-64}
for _ in $(seq 1 "$rounds"); do
  for bin in "$a" "$b"; do
    line=$("$bin" "$scene" "$size" "$samples" 5 | grep "DCS is")
    echo "$bin $(sed -E 's/.*DCS ([0-9.]+)s, reference ([0-9.]+)s.*/\1 \2/' <<<"$line")"
  done
done | awk '{ d[$1] += $2; r[$1] += $3; n[$1]++; print }
  END { for (k in d) printf "%s: mean DCS %.4f s, reference %.4f s, ratio %.3f\n", k, d[k] / n[k], r[k] / n[k], r[k] / d[k] }'
