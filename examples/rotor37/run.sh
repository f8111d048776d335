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
#    the blade's outside (side -), scallop ≤ 0.01 mm, chords within
#    0.003 mm, 5 % of the chord left at each edge and the tip row
#    (blade/shroud intersection) left out. The wheel is 2 mm wide: the blade
#    is concave across the passes, and a wider straight wheel's edges cut
#    under the surface (6 mm: 0.052 mm, see README.md).
#    Placement (work offset) for the MTS1600's travel: the blade turned
#    180° about the part's z axis, then moved by (-100, -10, 20) mm, which
#    lays its span along the A axis (part x) at x = -352 … -278, between
#    the machine file's fixture jaws and clear of its tailstock.
kinpost path "$out/rotor37-side1.json" --tool wheel:radius=20,width=2 \
  --direction v --side - --scallop 0.01 --chordtol 0.003 \
  --region 0,0.9,0.05,0.95 --feed 1200 --pressure H1=3000 \
  --rotate z:180 --translate -100,-10,20 --name ROTOR37_S1 \
  -o "$out/rotor37-side1.cls" --svg "$out/rotor37-side1-path.svg" \
  --json "$out/rotor37-side1-path.json"

# 3. Post on the MTS1600 (6-axis: the CL carries the feed direction, so
#    C turns the wheel), with the closed-loop check summary.
kinpost post "$out/rotor37-side1.cls" --machine mts1600 \
  -o "$out/rotor37-side1.mpf" --json "$out/rotor37-side1-post.json"

# 4. Grind the blade on the virtual machine: the stock is the blade side
#    0.1 mm proud (a 2.1 mm shell over the ground region), the program
#    replayed on the mts1600 with its 2 mm wheel, the part compared with
#    the design surface placed as the path placed the CL. Exit code 3 (a
#    gouge beyond 0.01 mm, a collision) stops the script.
kinpost surface place "$out/rotor37-side1.json" --rotate z:180 \
  --translate -100,-10,20 -o "$out/rotor37-side1-placed.json"
kinpost sim "$out/rotor37-side1.mpf" --machine mts1600 \
  --stock design+0.1 --design "$out/rotor37-side1-placed.json" \
  --design-side - --design-region 0,0.9,0.05,0.95 \
  --tool wheel:20,2 --resolution 0.05 \
  --json "$out/rotor37-side1-sim.json" --svg-out "$out/rotor37-side1-deviation.svg"
