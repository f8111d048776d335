#!/usr/bin/env bash
# NASA Rotor 37, blade side 1: measured points → B-spline surface → belt-
# grinding path → NC program for the MTS1600 grinder, checked in closed loop.
# Run from the repository root:  bash examples/rotor37/run.sh [OUTDIR]
# (set KINPOST to use an installed kinpost instead of cargo run).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-target/rotor37}
mkdir -p "$out"
kinpost() {
  if [ -n "${KINPOST:-}" ]; then "$KINPOST" "$@"; else cargo run --release --quiet -- "$@"; fi
}
data=data/nasa-rotors/rotor37geometry.dat

# 1. Side 1 (THETA 1) of the blade as a 13 × 100 grid in mm, fitted with
#    chord-length parameters (the table's points crowd at the edges).
kinpost surface fit "$data" --blade-side 1 --params chord-length \
  --write-grid "$out/rotor37-side1-grid.csv" -o "$out/rotor37-side1.json"
kinpost surface plot "$out/rotor37-side1.json" --curvature mean \
  --title "NASA Rotor 37, blade side 1" --svg "$out/rotor37-side1.svg"

# 2. Grinding passes from leading to trailing edge (along v), the wheel on
#    the blade's outside (side -), scallop ≤ 0.01 mm, 5 % of the chord left
#    at each edge and the tip row (blade/shroud intersection) left out.
#    Placement (work offset) for the MTS1600's travel: the blade turned
#    180° about the part's z axis, then moved by (-400, -10, 20) mm, which
#    lays its span along the A axis (part x) at x = -652 … -578.
kinpost path "$out/rotor37-side1.json" --tool wheel:radius=20,width=6 \
  --direction v --side - --scallop 0.01 --chordtol 0.01 \
  --region 0,0.9,0.05,0.95 --feed 1200 --pressure H1=3000 \
  --rotate z:180 --translate -400,-10,20 --name ROTOR37_S1 \
  -o "$out/rotor37-side1.cls" --svg "$out/rotor37-side1-path.svg" \
  --json "$out/rotor37-side1-path.json"

# 3. Post on the MTS1600 (6-axis: the CL carries the feed direction, so
#    C turns the wheel), with the closed-loop check summary.
kinpost post "$out/rotor37-side1.cls" --machine mts1600 \
  -o "$out/rotor37-side1.mpf" --json "$out/rotor37-side1-post.json"
