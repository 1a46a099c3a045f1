"""The AXI4-Stream top's documented interface, read from what the export wrote.

The export writes photon_search_axis.json beside photon_search_axis.v; the Verilog
header carries the same layout as a table of bit ranges. This module reads the
JSON, checks every row of the header table against it (so the two cannot drift),
and packs and unpacks tdata by field name. Nothing here knows the core's widths:
they all come from the files.
"""

import json
import re
from pathlib import Path

ROW = re.compile(
    r"^//\s+\|\s*(\w+) \((\d+) bytes\)\s*\|\s*\[(\d+)(?::(\d+))?\]\s*\|\s*(\w+)\s*\|"
)


class Stream:
    def __init__(self, name, spec):
        self.name = name
        self.tdata_bits = spec["tdata_bits"]
        self.fields = {f["name"]: (f["lsb"], f["width"]) for f in spec["fields"]}

    @property
    def tdata_bytes(self):
        return self.tdata_bits // 8

    def pack(self, **values):
        """tdata (as an int) with each named field set; unnamed fields are zero."""
        word = 0
        for name, v in values.items():
            lsb, width = self.fields[name]
            v = int(v)
            if v < 0 or v >> width:
                raise ValueError(f"{self.name}.{name} = {v} does not fit {width} bits")
            word |= v << lsb
        return word

    def pack_bytes(self, **values):
        return self.pack(**values).to_bytes(self.tdata_bytes, "little")

    def unpack(self, word):
        return {n: (word >> lsb) & ((1 << w) - 1) for n, (lsb, w) in self.fields.items()}

    def padding_mask(self):
        """The tdata bits no field uses: documented as zero."""
        used = 0
        for lsb, w in self.fields.values():
            used |= ((1 << w) - 1) << lsb
        return ((1 << self.tdata_bits) - 1) & ~used


class Layout:
    def __init__(self, export_dir):
        export_dir = Path(export_dir)
        spec = json.loads((export_dir / "photon_search_axis.json").read_text())
        self.core = spec["core"]
        self.streams = {n: Stream(n, s) for n, s in spec["streams"].items()}
        self.check_header(export_dir / "photon_search_axis.v")

    def __getitem__(self, name):
        return self.streams[name]

    def check_header(self, verilog_path):
        """Every field of the JSON is a row of the Verilog header's table and back."""
        rows = {}
        for line in Path(verilog_path).read_text().splitlines():
            if line.startswith("module "):
                break
            m = ROW.match(line)
            if m:
                stream, nbytes, hi, lo, field = m.groups()
                hi = int(hi)
                lo = hi if lo is None else int(lo)
                rows[(stream, field)] = (int(nbytes), lo, hi - lo + 1)
        table = {
            (s.name, f): (s.tdata_bytes, lsb, w)
            for s in self.streams.values()
            for f, (lsb, w) in s.fields.items()
        }
        if rows != table:
            raise AssertionError(
                f"the Verilog header's layout table and the JSON differ:\n"
                f"header only: {sorted(set(rows.items()) - set(table.items()))}\n"
                f"JSON only: {sorted(set(table.items()) - set(rows.items()))}"
            )
