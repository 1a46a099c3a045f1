#!/usr/bin/env bash
# ISE 14.7 flow for the paper's Virtex-6 (XC6VSX475T-2FF1759), 215 MHz constraint:
#   xst -> ngdbuild -> map -> par -> trce, then the numbers of paper Table 2.
# Usage (on a machine with ISE 14.7 and its settings64.sh sourced):
#   synth/ise/run_ise.sh [export-verilog options, e.g. --k 10 --metric l1]
# It cannot run on the project's CI machines (ISE is proprietary and Virtex-6 has no
# open timing model); see README.md, "Synthesis".
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here"
for tool in xst ngdbuild map par trce; do
  command -v "$tool" >/dev/null || { echo "error: $tool not on PATH (source ISE's settings64.sh)" >&2; exit 2; }
done
mkdir -p build/xst_tmp build/xst
# Export the core's Verilog (top module "top") with the requested configuration;
# without options, the paper's core (K = 10, 10-bit, L1, H = 10, 2 x 21 QueryModules).
[ $# -gt 0 ] || set -- --k 10 --bits 10 --address-bits 10 --metric l1 --queries-per-port 21
cargo run --release --quiet --manifest-path ../../Cargo.toml -- \
  export-verilog "$@" --out build
[ -f build/photon_search_core.v ] || { echo "error: export produced no build/photon_search_core.v" >&2; exit 2; }

part=xc6vsx475t-2-ff1759
xst -ifn photon_core.xst -ofn build/photon_core.syr
ngdbuild -p "$part" -uc photon_core.ucf -dd build/ngo build/photon_core.ngc build/photon_core.ngd
map -p "$part" -w -ol high -o build/photon_core_map.ncd build/photon_core.ngd build/photon_core.pcf
par -w -ol high build/photon_core_map.ncd build/photon_core.ncd build/photon_core.pcf
trce -v 10 -o build/photon_core.twr build/photon_core.ncd build/photon_core.pcf

# The numbers of paper Table 2 and §5.
mrp=build/photon_core_map.mrp
{
  echo "# ISE results ($part, $(date -u +%Y-%m-%d))"
  grep -E "Number of Slice LUTs:|Number of Slice Registers:|Number of occupied Slices:|Number of RAMB36E1/FIFO36E1s:|Number of RAMB18E1/FIFO18E1s:|Number of DSP48E1s:" "$mrp" || true
  grep -E "Minimum period:|Maximum frequency" build/photon_core.twr || true
} | tee build/ise_summary.txt
