#!/bin/bash
# The peer comparison of docs/speed.md ("Against open peers"): the same undamped cantilever released
# under gravity (gravity-release.toml) in gvsrom, PyElastica and soromox, each at several
# resolutions, every run's tip compared with gvsrom's converged run.
#
#   scripts/peers/run.sh OUT        # OUT: a new directory; 4–6 minutes with the venvs' install
#
# Writes OUT/table.md (docs/speed.md's table) and OUT/peers.png (tip traces; error against time).
#
# Installs PyElastica 1.0.0 and soromox 0.5.0 into venvs under OUT (pip reaches PyPI) and uses
# target/release/gvsrom (built if absent; GVSROM=path to use another). Writes nothing outside OUT.
set -euo pipefail
OUT=${1:?usage: scripts/peers/run.sh OUT}
[ -e "$OUT" ] && { echo "run.sh: $OUT exists; give a new directory (nothing is overwritten)" >&2; exit 2; }
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
B=${GVSROM:-$ROOT/target/release/gvsrom}
[ -x "$B" ] || (cd "$ROOT" && cargo build --release -p gvsrom)
mkdir -p "$OUT"
for peer in pyelastica soromox; do
  python3 -m venv "$OUT/venv-$peer"
done
"$OUT/venv-pyelastica/bin/pip" install -q "pyelastica==1.0.0" matplotlib
"$OUT/venv-soromox/bin/pip" install -q "soromox==0.5.0"
S="$HERE/gravity-release.toml"
RUNS=()

# gvsrom: Legendre order k in all six strains (6 (k + 1) DOF), the default adaptive integrator;
# three runs of each, timed by their median
"$B" simulate "$S" --set divisions.0.basis.order=10 --duration 1 --rtol 1e-8 --atol 1e-10 \
  --out "$OUT/gvsrom-ref" > "$OUT/gvsrom-ref.log"
for k in 2 3 4 6 8; do
  for i in 1 2 3; do
    "$B" simulate "$S" --set divisions.0.basis.order=$k --duration 1 --out "$OUT/gvsrom-k$k-$i" > "$OUT/gvsrom-k$k-$i.log"
  done
  RUNS+=("gvsrom, order $k=$OUT/gvsrom-k$k-1|$OUT/gvsrom-k$k-2|$OUT/gvsrom-k$k-3")
done

# PyElastica: n elements, dt = 4e-3 / n: at 50 elements the largest step dividing the output period
# that stays stable (1e-4 diverges), scaled with the element length (a step 0.625× as long changes no digit of
# the error)
for n in 50 100 200 400; do
  dt=$(python3 -c "print(4e-3 / $n)")
  "$OUT/venv-pyelastica/bin/python" "$HERE/pyelastica_release.py" --elements $n --dt $dt \
    --repeat 3 --out "$OUT/pyelastica-n$n" > "$OUT/pyelastica-n$n.log"
  RUNS+=("PyElastica, $n elements=$OUT/pyelastica-n$n")
done
RUNS+=("PyElastica, extrapolated=$OUT/pyelastica-n200+$OUT/pyelastica-n400")

# soromox: its GVS (one segment, Legendre order k: the same model class as gvsrom's) and PCS
# (N segments of constant strain), all six strains, diffrax's Tsit5 at rtol 1e-4 as gvsrom's (the
# stiff modes, not the tolerance, set its step: rtol 1e-6 takes 1.3–1.9× the steps for the same tip),
# its explicit solvers being what it offers in practice (Kvaerno5 took 122 s for PCS N = 4), and
# its own semi-implicit Euler at a fixed step
SX="$OUT/venv-soromox/bin/python $HERE/soromox_release.py --repeat 1 --rtol 1e-4 --atol 1e-6"
for k in 1 2 3; do
  $SX --model gvs --segments 1 --order $k --out "$OUT/soromox-gvs-k$k" > "$OUT/soromox-gvs-k$k.log"
  RUNS+=("soromox GVS, order $k=$OUT/soromox-gvs-k$k")
done
for n in 4 8; do
  $SX --model pcs --segments $n --out "$OUT/soromox-pcs-n$n" > "$OUT/soromox-pcs-n$n.log"
  RUNS+=("soromox PCS, $n segments=$OUT/soromox-pcs-n$n")
done
$SX --model pcs --segments 4 --solver sie --dt 1e-4 --out "$OUT/soromox-pcs-n4-sie" > "$OUT/soromox-pcs-n4-sie.log"
RUNS+=("soromox PCS semi-implicit Euler, 4 segments=$OUT/soromox-pcs-n4-sie")

"$OUT/venv-pyelastica/bin/python" "$HERE/compare.py" --figure "$OUT/peers.png" "$OUT/gvsrom-ref" "${RUNS[@]}" \
  | tee "$OUT/table.md"
