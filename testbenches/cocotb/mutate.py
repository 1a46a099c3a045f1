"""Make a deliberately broken copy of an export, for the check that the testbench
rejects it: the same files (the layout table and JSON unchanged), with
photon_search_axis.v rewired.

    python mutate.py --export DIR --out BROKEN_DIR --mutation swap-xy|no-tlast

swap-xy: the query's x and y tdata fields feed each other's core field.
no-tlast: m_axis_result_tlast is tied low.
"""

import argparse
import re
import shutil
import sys
from pathlib import Path


def swap_xy(v):
    # `assign query_data[..] = s_axis_query_tdata[HI:LO]; // x` and the same for y.
    pat = re.compile(r"^(\s*assign query_data\[[^\]]+\] = )(s_axis_query_tdata\[[^\]]+\]); // ([xy])$", re.M)
    rhs = {m.group(3): m.group(2) for m in pat.finditer(v)}
    if set(rhs) != {"x", "y"}:
        sys.exit("error: query x/y assignments not found")
    other = {"x": rhs["y"], "y": rhs["x"]}
    return pat.sub(lambda m: f"{m.group(1)}{other[m.group(3)]}; // {m.group(3)}", v)


def no_tlast(v):
    out, n = re.subn(r"assign m_axis_result_tlast = [^;]+;", "assign m_axis_result_tlast = 1'b0;", v)
    if n != 1:
        sys.exit("error: m_axis_result_tlast assignment not found")
    return out


MUTATIONS = {"swap-xy": swap_xy, "no-tlast": no_tlast}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--export", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--mutation", choices=sorted(MUTATIONS), required=True)
    args = ap.parse_args()
    if args.out.exists():
        shutil.rmtree(args.out)
    args.out.mkdir(parents=True)
    for f in ("photon_search_core.v", "photon_search_core_sim.v", "photon_search_axis.json"):
        shutil.copy(args.export / f, args.out / f)
    v = (args.export / "photon_search_axis.v").read_text()
    broken = MUTATIONS[args.mutation](v)
    assert broken != v
    (args.out / "photon_search_axis.v").write_text(broken)
    print(f"wrote {args.out}: {args.mutation}")


if __name__ == "__main__":
    main()
