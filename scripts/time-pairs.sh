#!/usr/bin/env bash
# Wall time of a reduced model against the HOM on the IV-C2 test input, in interleaved pairs (the
# shared machine's drift cancels within a pair): N rounds of `gvsrom simulate six-tendon` (HOM),
# then the same with `--model MODEL`, each writing its trajectory; prints every round's ratio
# AE-ROM / HOM (the integration time `simulate` prints) and their median.
#   scripts/time-pairs.sh MODEL SEED [N=9] [GVSROM=target/release/gvsrom] [SCENARIO=six-tendon]
set -euo pipefail
model=$1 seed=$2 n=${3:-9} bin=${4:-target/release/gvsrom} scenario=${5:-six-tendon}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
wall() { "$bin" simulate "$scenario" --duration 10 --steps=-15,0,1 --seed "$seed" "$@" 2>&1 |
    sed -n 's/.* in \([0-9.]*\) s wall time.*/\1/p'; }
ratios=()
for i in $(seq 1 "$n"); do
    h=$(wall --out "$out/hom-$i")
    a=$(wall --model "$model" --out "$out/rom-$i")
    ratios+=("$(python3 -c "print(f'{$a / $h:.3f}')")")
done
median=$(printf '%s\n' "${ratios[@]}" | sort -n | python3 -c "import sys, statistics; print(f'{statistics.median(float(x) for x in sys.stdin):.3f}')")
echo "seed $seed: ${ratios[*]}; median $median"
