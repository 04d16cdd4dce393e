#!/bin/sh
# Regenerates cantilever-tip.csv, the converged tip history of scenes/cantilever.toml:
# the same scene refined 5 times (lattice 200 x 200, h = 0.05; particles 0.025 apart,
# whose lattice contains the coarse probe particle at (3.9375, 0.4375)) run with
# quadratic B-splines, which do not depend on the mesh or its rotation. Run from the
# repository root: sh scenes/data/make_cantilever_reference.sh [KERNEL] [REFINE]
set -e
kernel=${1:-bspline2}
refine=${2:-5}
cells=$((40 * refine))
spacing=$(python3 -c "print(0.125 / $refine)")
tmp=$(mktemp -d)
sed -e "s/cells = \[40, 40\]/cells = [$cells, $cells]/" \
    -e "s/spacing = 0.125,/spacing = $spacing,/" \
    -e '/^\[reference.probe\]/,$d' \
    scenes/cantilever.toml > "$tmp/cantilever.toml"
cargo run --release -q -p umls-cli -- run "$tmp/cantilever.toml" --kernel "$kernel" \
    --out "$tmp/out" --quiet
python3 - "$tmp/out/history.csv" <<'PY' > scenes/data/cantilever-tip.csv
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("time,ux,uy")
for r in rows:
    print(f"{float(r['time']):.6f},{float(r['probe0_ux']):.6e},{float(r['probe0_uy']):.6e}")
PY
rm -rf "$tmp"
