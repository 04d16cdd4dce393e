#!/bin/sh
# Regenerates cantilever-3d-tip.csv, the converged probe history of
# scenes/cantilever-3d.toml: the same scene refined 9 times (Kuhn cells 0.25/9,
# particles 0.125/9 apart, 279,936 of them; every odd refinement keeps a particle at the
# probe (2.4375, 0.1875, 0.1875)) run with quadratic B-splines, which do not depend on
# the tetrahedra, held on the clamp's face as the scene is. About 30 minutes on two
# cores. The run writes a row every step (6,266 of them); every fourth is kept, which
# leaves linear interpolation between rows below 10^-6 of the deflection.
# Run from the repository root:
#   sh scenes/data/make_cantilever_3d_reference.sh [KERNEL] [REFINE]
set -e
kernel=${1:-bspline2}
refine=${2:-9}
tmp=$(mktemp -d)
sed -e '/^\[reference.probe\]/,$d' scenes/cantilever-3d.toml > "$tmp/cantilever-3d.toml"
cargo run --release -q -p umls-cli -- run "$tmp/cantilever-3d.toml" --kernel "$kernel" \
    --refine "$refine" --out "$tmp/out" --quiet
python3 - "$tmp/out/history.csv" <<'PY' > scenes/data/cantilever-3d-tip.csv
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
kept = rows[::4]
if kept[-1] is not rows[-1]:
    kept.append(rows[-1])
print("time,ux,uy,uz")
for r in kept:
    print(f"{float(r['time']):.7f},{float(r['probe0_ux']):.6e},"
          f"{float(r['probe0_uy']):.6e},{float(r['probe0_uz']):.6e}")
PY
rm -rf "$tmp"
