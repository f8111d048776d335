#!/usr/bin/env bash
# The papers' grinding experiments on the virtual MTS1600 (see README.md):
#   (a) Qiao et al. 2022 §4.1: the flat-part program of Figure 28 grinding
#       a 400 × 100 × 7.5 mm blank with the 25 mm wide contact wheel;
#   (b) Qi (thesis) §4.2–4.3: two traces, the wheel at the upper and at the
#       lower stop of the pressure axis H1, posted with and without the
#       compensation of the wheel's offset, and ground by the process model.
# Run from the repository root:  bash examples/grinding-experiments/run.sh [OUTDIR]
# (set KINPOST to use an installed kinpost instead of cargo run).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-target/grinding-experiments}
here=examples/grinding-experiments
mkdir -p "$out"
kinpost() {
  if [ -n "${KINPOST:-}" ]; then "$KINPOST" "$@"; else cargo run --release --quiet -- "$@"; fi
}
# The part is compared with its surface before grinding, so every point
# ground is "below the design" and sim exits with 3: here that is the depth
# ground, what the experiment measures.
sim() { kinpost sim "$@" || [ $? -eq 3 ]; }

# (a) The blank's top is z = 1.5 (the plate's is z = 0, Qiao et al. §4.1.2).
kinpost post examples/flat-part.cls --machine mts1600 -o "$out/flat-part.mpf"
sim "$out/flat-part.mpf" --machine mts1600 \
  --stock box:-452,0,-6,-52,100,1.5 --tool wheel:50,25 --resolution 0.05 \
  --design "$here/blank-top.json" \
  --json "$out/flat-part-sim.json" --svg-out "$out/flat-part-depth.svg"

# (b) Two traces 20 mm deep into an 80 mm test block, the first at the upper
#     stop (H1 = 3600), the second at the lower stop (H1 = 3000).
kinpost post "$here/two-traces.cls" --machine mts1600 -o "$out/traces.mpf"
kinpost post "$here/two-traces.cls" --machine mts1600 \
  --no-pressure-compensation -o "$out/traces-uncompensated.mpf"
for program in traces traces-uncompensated; do
  sim "$out/$program.mpf" --machine mts1600 \
    --stock box:-452,60,-80,-52,160,0 --tool wheel:50,25 --resolution 0.1 \
    --design "$here/block-top.json" --json "$out/$program-sim.json"
done
# The compensated program ground by the process model: Preston's law at the
# force the pressure word gives (crates/stock/process/mts1600.toml).
sim "$out/traces.mpf" --machine mts1600 \
  --stock box:-452,60,-80,-52,160,0 --tool wheel:50,25 --resolution 0.1 \
  --design "$here/block-top.json" --process crates/stock/process/mts1600.toml \
  --json "$out/traces-process-sim.json"
