#!/usr/bin/env bash
# The ECP5 cells of one exported core as Debian yosys (0.23) maps it, for the area
# comparisons of docs/HARDWARE.md that are not synth/report.py rows (one core in two
# variants, no place and route):
#
#   synth/ecp5_area.sh --controller barrel --traversal cell --k 32 --metric l2 \
#       --address-bits 16 --radius-bits 14
#
# The arguments are export-verilog's. Prints the LUT4, CCU2C (two LUT4 sites each),
# DPR16X4, FF, DP16KD and wide-multiplexer counts of the whole design (synth_ecp5,
# flattened). Needs: cargo, yosys (apt-get install yosys).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here/.."
command -v yosys >/dev/null || { echo "error: yosys not found (apt-get install yosys)" >&2; exit 2; }
cargo build --release --quiet
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
target/release/photon-fpga export-verilog "$@" --out "$dir" >/dev/null
yosys -q -p "read_verilog $dir/photon_search_core.v; synth_ecp5 -top top; tee -q -o $dir/stat.txt stat" >"$dir/yosys.log" 2>&1 ||
  { cat "$dir/yosys.log" >&2; exit 1; }
echo "Debian yosys $(yosys -V | cut -d' ' -f2) synth_ecp5 of export-verilog $*"
grep -E "^ +(LUT4|CCU2C|TRELLIS_DPR16X4|TRELLIS_FF|DP16KD|PFUMX|L6MUX21) " "$dir/stat.txt"
