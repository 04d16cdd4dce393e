#!/bin/sh
# Regenerates a scene's converged probe history, scenes/data/SCENE-tip.csv: the scene
# itself refined (`umls run --refine`: its lattice's cells multiplied, its particle
# spacing divided) and run without its own [reference.probe], with quadratic B-splines,
# which do not depend on the mesh or its rotation. Run from the repository root:
#   sh scenes/data/make_probe_reference.sh SCENE [KERNEL] [REFINE]
#
# The references it makes, with the refinement and the rows they keep:
# - cantilever: cantilever-tip.csv, the reference of cantilever-unstructured too. Refined
#   5 times (lattice 200 x 200, h = 0.05; particles 0.025 apart, whose lattice contains
#   the coarse probe particle at (3.9375, 0.4375)), about 30 seconds; every row.
# - cantilever-3d: cantilever-3d-tip.csv. Refined 9 times (Kuhn cells 0.25/9, particles
#   0.125/9 apart, 279,936 of them; every odd refinement keeps a particle at the probe
#   (2.4375, 0.1875, 0.1875)), held on the clamp's face as the scene is; about 30
#   minutes on two cores. The run writes a row every step (6,266 of them); every fourth
#   is kept, which leaves linear interpolation between rows below 10^-6 of the
#   deflection.
set -e
scene=${1:?usage: make_probe_reference.sh SCENE [KERNEL] [REFINE]}
kernel=${2:-bspline2}
# The rows kept (every STRIDE-th and the last) and the digits of their times (the
# finest run's steps need seven).
case $scene in
    cantilever) refine=${3:-5} stride=1 digits=6 ;;
    cantilever-3d) refine=${3:-9} stride=4 digits=7 ;;
    *) echo "make_probe_reference.sh: no reference is made for scene '$scene'" >&2; exit 2 ;;
esac
tmp=$(mktemp -d)
sed -e '/^\[reference.probe\]/,$d' "scenes/$scene.toml" > "$tmp/$scene.toml"
cargo run --release -q -p umls-cli -- run "$tmp/$scene.toml" --kernel "$kernel" \
    --refine "$refine" --out "$tmp/out" --quiet
python3 - "$tmp/out/history.csv" "$stride" "$digits" <<'PY' > "scenes/data/$scene-tip.csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
stride, digits = int(sys.argv[2]), int(sys.argv[3])
axes = [a for a in "xyz" if f"probe0_u{a}" in rows[0]]
kept = rows[::stride]
if kept[-1] is not rows[-1]:
    kept.append(rows[-1])
print(",".join(["time"] + [f"u{a}" for a in axes]))
for r in kept:
    print(",".join([f"{float(r['time']):.{digits}f}"]
                   + [f"{float(r[f'probe0_u{a}']):.6e}" for a in axes]))
PY
rm -rf "$tmp"
