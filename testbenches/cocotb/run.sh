#!/usr/bin/env bash
# The cocotb stage of CI: the AXI4-Stream top (photon-fpga export-verilog --interface
# axis) under cocotb + cocotbext-axi in Icarus and Verilator, every result checked
# against the bench's own brute force; then two deliberately broken exports, which
# the bench must reject. Fails if a tool is missing.
#
#   testbenches/cocotb/run.sh [QUERIES]     (default 1000 queries on the first map)
#
# Needs the photon-fpga binary (target/{debug,release}, the newer one; or
# $PHOTON_FPGA_BIN), python3 with venv, iverilog, perl, g++ and make. The venv lives
# in $PHOTON_COCOTB_VENV (default target/cocotb-venv) and is reused when its pins match.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
queries="${1:-1000}"
target="${CARGO_TARGET_DIR:-$root/target}"

for t in python3 iverilog perl g++ make; do
  command -v "$t" >/dev/null || { echo "error: $t is not installed" >&2; exit 1; }
done
bin="${PHOTON_FPGA_BIN:-}"
if [ -z "$bin" ]; then
  for b in "$target/debug/photon-fpga" "$target/release/photon-fpga"; do
    if [ -x "$b" ] && { [ -z "$bin" ] || [ "$b" -nt "$bin" ]; }; then bin="$b"; fi
  done
fi
[ -n "$bin" ] && [ -x "$bin" ] || { echo "error: no photon-fpga binary (cargo build first)" >&2; exit 1; }

venv="${PHOTON_COCOTB_VENV:-$target/cocotb-venv}"
if ! cmp -s "$here/requirements.txt" "$venv/requirements.txt" 2>/dev/null; then
  rm -rf "$venv"
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt"
  cp "$here/requirements.txt" "$venv/requirements.txt"
fi
py="$venv/bin/python"
# Each Verilator build compiles Verilator's runtime with the same flags: with
# ccache installed, once.
if command -v ccache >/dev/null; then export OBJCACHE=ccache; fi
vroot="$("$py" -c 'import os, verilator; print(os.path.dirname(verilator.__file__))')"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The paper's core with the barrel controller, whose result beats carry photon pairs, in
# both simulators; in Verilator also the paper's controller (QueryModules, one
# photon a beat; Q = 4 keeps the model's build short) with the other metric and
# 12-bit coordinates (a 38-bit word in an 8-byte beat).
"$bin" export-verilog --interface axis --paper --controller barrel --out "$work/axis" >/dev/null
"$bin" export-verilog --interface axis --paper --queries-per-port 4 --metric l2 --bits 12 \
  --out "$work/modules" >/dev/null
# The banked core (the default core's K, metric and controller) with two result
# streams, so two result ports; four replicated levels, so the bench's maps reach
# the banks; in Verilator.
"$bin" export-verilog --interface axis --address-bits 12 --banks 8 --replicas 2 \
  --replicated-levels 4 --result-streams 2 --out "$work/banked" >/dev/null
# The external-memory core: four on-chip levels, the rest in the bench's AxiRamRead
# (pauses on AR and R) behind a cache of 16 lines in four banks, so that lines are
# replaced all the time; in Verilator.
"$bin" export-verilog --interface axis --address-bits 12 --banks 4 --replicas 1 \
  --replicated-levels 4 --cache-lines 16 --out "$work/memory" >/dev/null

export PYTHONDONTWRITEBYTECODE=1
tally="$work/tally"

# Each bench is one Python process, so the Icarus runs go beside the Verilator ones
# (two chains, both cores busy); Icarus's log is printed when both have ended.
# The bench must fail on a broken export (run.py --expect-fail exits 0 only if a
# test failed, non-zero if all passed or nothing ran).
(
  "$py" "$here/run.py" --sim icarus --export "$work/axis" --queries "$queries" --tally "$tally"
  "$py" "$here/mutate.py" --export "$work/axis" --out "$work/swap-xy" --mutation swap-xy
  "$py" "$here/run.py" --sim icarus --export "$work/swap-xy" --queries 50 --expect-fail --tally "$tally"
  "$py" "$here/mutate.py" --export "$work/axis" --out "$work/no-tlast" --mutation no-tlast
  "$py" "$here/run.py" --sim icarus --export "$work/no-tlast" --queries 50 --expect-fail --tally "$tally" \
    --test one_map_many_queries
) >"$work/icarus.log" 2>&1 &
icarus=$!
(
  export PATH="$vroot/bin:$PATH" VERILATOR_ROOT="$vroot"
  for core in axis modules banked; do
    "$py" "$here/run.py" --sim verilator --export "$work/$core" --queries "$queries" --tally "$tally"
  done
  # The memory core: the many-queries test (a second map and a reset are the Rust
  # testbenches' hw_memory_core, which the same export runs under Verilator).
  "$py" "$here/run.py" --sim verilator --export "$work/memory" --queries "$queries" --tally "$tally" \
    --test one_map_many_queries
  # A broken memory layout: the bench's image with its first two blocks swapped.
  PHOTON_AXIS_SWAP_BLOCKS=0,1 \
    "$py" "$here/run.py" --sim verilator --export "$work/memory" --queries 50 --expect-fail \
    --tally "$tally" --test one_map_many_queries --build "$work/memory/sim_build_swapped"
) &
verilator=$!
icarus_rc=0
wait "$icarus" || icarus_rc=$?
verilator_rc=0
wait "$verilator" || verilator_rc=$?
cat "$work/icarus.log"
if [ "$icarus_rc" -ne 0 ] || [ "$verilator_rc" -ne 0 ]; then
  echo "cocotb: failed (Icarus chain exit $icarus_rc, Verilator chain exit $verilator_rc)" >&2
  exit 1
fi
# Tests passed in both simulators plus the broken exports rejected.
echo "cocotb: $(awk '{ n += $1 } END { print n }' "$tally") passed, 0 failed"
