#!/usr/bin/env bash
# Issue 57's synthetic learning curve: Phys-NN+, Phys-Q (from Ferguson 2022's coefficients) and NN trained on 1k, 10k
# and all of the synthetic set's training shots, every validation shot kept (docs/accuracy.md). One torch thread a run,
# nice'd (a shared 2-core machine). Epochs and batch are one rule per n, the same for every variant: 800 optimiser steps
# at 1k (batch 256: the paper's 1024 would be the whole set, one step an epoch) and 10k, 25 epochs (1,975 steps) for
# the whole set, which fits the machine's afternoon (docs/accuracy.md). Outputs under build/ (git-ignored).
# ONLY=90000 trains one n; SEEDS="0 1 2" adds seeds (each a run of its own).
set -euo pipefail
cd "$(dirname "$0")/.."
work=${WORK:-build/synth-lc}
data=${DATA:-$work/synth90k.csv}
mkdir -p "$work"
[ -f "$data" ] || python3 -m golfflight synth --shots 90000 --seed 0 --out "$data"
declare -A epochs=([1000]=200 [10000]=80 [90000]=25) batch=([1000]=256 [10000]=1024 [90000]=1024)
for n in ${ONLY:-1000 10000 90000}; do
  file=$data
  if [ "$n" != 90000 ]; then
    file=$work/train$n.csv
    [ -f "$file" ] || python3 scripts/synthetic_learning_curve.py subset --data "$data" --train-shots "$n" --out "$file"
  fi
  for seed in ${SEEDS:-0}; do
    for variant in phys-nn+ phys-q nn; do
      run=$work/$variant-n$n-seed$seed
      [ -f "$run/history.json" ] && resume=--resume || resume=
      loss=lp+lh; [ "$variant" = nn ] && loss=lp
      nice python3 -m golfflight train --data "$file" --variant "$variant" --epochs "${epochs[$n]}" \
        --batch-size "${batch[$n]}" --loss "$loss" --seed "$seed" --threads 1 --quiet --out "$run" $resume
    done
  done
done
