"""Build photon_search_axis from an export directory and run the cocotb testbench
in one simulator (cocotb_tools.runner).

    python run.py --sim icarus|verilator --export DIR [--queries N] [--build DIR]
                  [--expect-fail]

Icarus simulates photon_search_core_sim.v (the export's glitch-free rewrite for
event-driven simulators), Verilator photon_search_core.v. Exit status 0 iff every
test passed (with --expect-fail: iff some test failed, for the broken-export check).
Prints the queries checked and the wall time.
"""

import argparse
import os
import shutil
import sys
import time
from pathlib import Path

from cocotb_tools.check_results import get_results
from cocotb_tools.runner import get_runner


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", choices=["icarus", "verilator"], required=True)
    ap.add_argument("--export", type=Path, required=True, help="export-verilog --interface axis output")
    ap.add_argument("--queries", type=int, default=1000, help="queries on the first map")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--build", type=Path, help="build directory [default: EXPORT/sim_build_SIM]")
    ap.add_argument("--test", help="run only this test of test_photon_axis")
    ap.add_argument("--tally", type=Path, help="append the checks passed to this file")
    ap.add_argument("--expect-fail", action="store_true", help="succeed iff a test fails")
    args = ap.parse_args()

    export = args.export.resolve()
    core = "photon_search_core_sim.v" if args.sim == "icarus" else "photon_search_core.v"
    sources = [export / core, export / "photon_search_axis.v"]
    for s in sources + [export / "photon_search_axis.json"]:
        if not s.is_file():
            sys.exit(f"error: {s}: missing (run photon-fpga export-verilog --interface axis)")
    build = (args.build or export / f"sim_build_{args.sim}").resolve()
    if build.exists():
        shutil.rmtree(build)
    build_args = []
    if args.sim == "verilator":
        if shutil.which("verilator") is None:
            sys.exit("error: verilator not on PATH")
        # rust-hdl's export has width mismatches Verilator warns about.
        build_args = ["-Wno-fatal", "-Wno-WIDTH", "-Wno-lint", "-Wno-style"]
        # The PyPI wheel's verilated.mk keeps the tool paths and flags of the machine
        # it was built on (its own compiler path, no precompiled-header option, no
        # thread library); make takes command-line variables from MAKEFLAGS, which
        # override them. The Python bench, not the model, sets the pace, so the
        # model is compiled without optimisation (the shortest build).
        fixes = (
            "AR=ar CXX=g++ LINK=g++ PERL=perl PYTHON3=python3 CFG_CXXFLAGS_PCH_I=-include "
            "CFG_LDLIBS_THREADS=-pthread OPT_FAST=-O0 OPT_SLOW=-O0 OPT_GLOBAL=-O0"
        )
        os.environ["MAKEFLAGS"] = f"{os.environ.get('MAKEFLAGS', '')} {fixes}".strip()
    elif shutil.which("iverilog") is None:
        sys.exit("error: iverilog not on PATH")

    t0 = time.monotonic()
    runner = get_runner(args.sim)
    runner.build(
        sources=sources,
        hdl_toplevel="photon_search_axis",
        build_dir=build,
        build_args=build_args,
        timescale=("1ns", "1ps"),
        always=True,
    )
    t1 = time.monotonic()
    xml = runner.test(
        hdl_toplevel="photon_search_axis",
        test_module="test_photon_axis",
        test_dir=build,
        build_dir=build,
        results_xml=str(build / "results.xml"),
        testcase=args.test,
        extra_env={
            "PHOTON_AXIS_DIR": str(export),
            "PHOTON_AXIS_QUERIES": str(args.queries),
            "PHOTON_AXIS_SEED": str(args.seed),
            "PYTHONDONTWRITEBYTECODE": "1",
        },
    )
    t2 = time.monotonic()
    tests, failed = get_results(xml)
    print(
        f"cocotb {args.sim}: {tests} tests, {failed} failed; build {t1 - t0:.0f} s, "
        f"run {t2 - t1:.0f} s ({export.name})"
    )
    if tests == 0:
        print("error: no test ran")
        return 1
    ok = failed == 0
    if args.expect_fail:
        if ok:
            print(f"error: the testbench passed on {export}, which it must reject")
            return 1
        print(f"as expected, the testbench rejected {export}")
        passed = 1
    elif not ok:
        return 1
    else:
        passed = tests
    if args.tally:
        with open(args.tally, "a") as f:
            f.write(f"{passed}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
