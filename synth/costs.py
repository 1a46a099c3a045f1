"""The device planner's logic costs, derived from the part syntheses of
synth/results.json (`Config.cost_parts` in report.py): written to
synth/device_costs.toml, which src/host/device/devices.rs reads, and listed in
synth/REPORT.md. `python3 synth/report.py render` regenerates both.

Each cost is one part's cells (a barrel datapath, the banks' crossbar, one cache
bank, the rest of an external-memory core) as yosys maps it for the device family,
divided by what it scales with; the planner multiplies them back up
(src/host/device/plan.rs)."""
import os
from dataclasses import dataclass

HERE = os.path.dirname(os.path.abspath(__file__))
COSTS_FILE = os.path.join(HERE, "device_costs.toml")

# The rows whose parts the costs come from (report.py's CONFIGS).
BANKED = "banked D=8 (K=32, L2, 4x2x16 slots, B=16 split, R=2, Cornell 65 K photons)"
SHARED = "banked D=8, shared ports (K=32, L2, 4x2x16 slots, B=16 shared, R=2: crossbar only)"
MEMORY = ("external memory D=4, K=32 (L2, 2x2x16 slots, B=16 split, T=9, 1024 lines, 64-bit memory, "
          "Cornell 1.9 M photons)")
MEMORY_2X = "external memory D=4, K=32, 2048 lines (L2, B=16 split, T=9, 64-bit memory: cache bank only)"
MEMORY_LUT_TAGS = ("external memory D=4, K=500 (L2, 2x2x16 slots, B=16 split, T=9, 1024 lines, LUT-RAM tags, "
                   "64-bit memory, Cornell 1.9 M photons)")

# The devices (the planner's `Device::key`): the family whose counts each takes,
# and what its logic cell is called.
DEVICES = [("ecp5_85k", "ECP5-85k", "ecp5", "LUT4s"), ("xc6vsx475t", "XC6VSX475T", "xc6v", "LUTs")]


@dataclass
class Cost:
    key: str
    value: float
    # How it was made, with the counts it was made from.
    formula: str
    # The rows it reads and whether any was measured on an earlier Verilog.
    rows: list
    stale: bool


def part_luts(r, family, part):
    """A row's part's logic cells: ECP5 LUT4 sites (Ecp5Part.luts), or Virtex-6
    LUTs with each LUT-RAM primitive (RAM32M, RAM64M: four LUTs of a slice) as
    four."""
    if family == "ecp5":
        p = r.ecp5_parts.get(part)
        return p and p.luts
    p = r.parts.get(part)
    return p and p.luts + 4 * p.lutram


def datapaths(r):
    return 2 * r.core["replicas"]


def derive(rows, family, cell):
    """The costs for one family from `rows` ({name: Record}); a cost whose parts are
    missing is left out (devices.rs then cannot read the file: its test fails)."""
    out = []

    def get(name, part):
        r = rows.get(name)
        return (r, part_luts(r, family, part)) if r else (None, None)

    r, v = get(BANKED, "datapath")
    if v:
        out.append(Cost("datapath_luts", v, f"part datapath: {v:,} {cell}", [BANKED], r.stale))
    for key, name in (("crossbar_luts_split", BANKED), ("crossbar_luts_shared", SHARED),
                      ("memory_crossbar_luts", MEMORY)):
        r, v = get(name, "crossbar")
        if v:
            d, b = datapaths(r), r.core["banks"]
            out.append(Cost(key, v / (d * b), f"part crossbar {v:,} {cell} / (D = {d} x B = {b})",
                            [name], r.stale))
    memory_datapath(out, rows.get(MEMORY), family, cell)
    r1, a = get(MEMORY, "cache_bank")
    r2, a2 = get(MEMORY_2X, "cache_bank")
    if a and a2:
        n1 = r1.core["cache_lines"] // r1.core["banks"]
        n2 = r2.core["cache_lines"] // r2.core["banks"]
        line = (a2 - a) / (n2 - n1)
        out.append(Cost("cache_line_luts", line,
                        f"(part cache_bank at {n2} lines a bank {a2:,} - at {n1} lines {a:,}) / {n2 - n1} lines",
                        [MEMORY_2X, MEMORY], r1.stale or r2.stale))
        out.append(Cost("cache_bank_luts", a - n1 * line,
                        f"part cache_bank at {n1} lines a bank {a:,} - {n1} x cache_line_luts",
                        [MEMORY, MEMORY_2X], r1.stale or r2.stale))
    r3, a3 = get(MEMORY_LUT_TAGS, "cache_bank")
    if a and a3:
        # The same bank but for its tags: LUT-RAM copies only as wide as the map's
        # tags against BlockRAM ones 24 bits wide (and their compare), per line.
        n = r3.core["cache_lines"] // r3.core["banks"]
        assert n == r1.core["cache_lines"] // r1.core["banks"], "the same lines a bank"
        out.append(Cost("cache_lut_tag_luts", (a3 - a) / n,
                        f"(part cache_bank with LUT-RAM tags {a3:,} - with BlockRAM tags {a:,}) / {n} lines",
                        [MEMORY_LUT_TAGS, MEMORY], r1.stale or r3.stale))
    r, v = get(MEMORY, "memory_rest")
    if v:
        out.append(Cost("memory_rest_luts", v, f"part memory_rest: {v:,} {cell}", [MEMORY], r.stale))
    return out


def memory_datapath(out, r, family, cell):
    """An external-memory core's datapath: where the whole core was placed, what
    its LUT4 count (nextpnr's, before packing) leaves beside its other parts, so
    that the parts add up to the placed core (synthesised whole, yosys removes
    across the parts' boundaries logic each part alone keeps: about a tenth);
    else the part as synthesised alone."""
    if r is None:
        return
    v = part_luts(r, family, "datapath")
    used = r.ecp5 and r.ecp5.used and r.ecp5.used.get("Total LUT4s") if family == "ecp5" else None
    others = [part_luts(r, family, p) for p in ("crossbar", "cache_bank", "memory_rest")]
    d, b = datapaths(r), r.core["banks"]
    if used and all(others):
        x, bank, rest = others
        v = (used[0] - x - b * bank - rest) / d
        out.append(Cost("memory_datapath_luts", round(v),
                        f"(placed core {used[0]:,} {cell} - part crossbar {x:,} - {b} x part cache_bank "
                        f"{bank:,} - part memory_rest {rest:,}) / D = {d}", [r.name], r.stale))
    elif v:
        out.append(Cost("memory_datapath_luts", v, f"part datapath: {v:,} {cell}", [r.name], r.stale))


def all_costs(records):
    rows = {r.name: r for r in records}
    return [(key, name, cell, derive(rows, family, cell)) for key, name, family, cell in DEVICES]


def render_toml(records):
    L = ["# The device planner's logic costs (src/host/device/devices.rs), generated by",
         "# `python3 synth/report.py render` from the part syntheses in synth/results.json",
         "# (synth/costs.py says how): do not edit; `synth/run.sh ROW` re-measures a row."]
    for key, name, cell, costs in all_costs(records):
        L += ["", f"[{key}]"]
        for c in costs:
            L.append(f"# {name}: {c.formula}; {', '.join(repr(n) for n in c.rows)}"
                     + (" [stale]" if c.stale else ""))
            L.append(f"{c.key} = {round(c.value, 3)!r}")
    return "\n".join(L) + "\n"


def render_section(records):
    """REPORT.md's section of the planner's costs."""
    L = ["\n## Device planner costs\n",
         "The logic each part of a banked or external-memory core costs, as `--device` plans "
         "(`src/host/device/plan.rs`), from each part synthesised as its own top (*synthesised*: Debian yosys "
         "`synth_ecp5` and `synth_xilinx -family xc6v`, both without the share pass; an ECP5 part's LUT4 sites "
         "as nextpnr counts them before packing). Generated into `synth/device_costs.toml` by "
         "`synth/costs.py`.\n",
         "| device | cost | value | from | rows |", "|---|---|---:|---|---|"]
    for _, name, cell, costs in all_costs(records):
        for c in costs:
            rows = "; ".join(c.rows) + (" [stale]" if c.stale else "")
            L.append(f"| {name} | `{c.key}` | {c.value:,.2f} | {c.formula} | {rows} |")
    return L


def write(records):
    text = render_toml(records)
    with open(COSTS_FILE + ".tmp", "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(COSTS_FILE + ".tmp", COSTS_FILE)


def differs(records):
    return not os.path.exists(COSTS_FILE) or open(COSTS_FILE, encoding="utf-8").read() != render_toml(records)
