"""cocotb testbench of photon_search_axis, written against its documented interface
(the tdata layout table of the Verilog header and photon_search_axis.json) only.

Each test drives the three streams with cocotbext-axi (random pauses on both
inputs, random back-pressure on the output) and checks every result against the
brute force of model.py. Environment: PHOTON_AXIS_DIR (the export directory),
PHOTON_AXIS_QUERIES (queries of the first map; the others scale with it),
PHOTON_AXIS_SEED.
"""

import logging
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.queue import Queue
from cocotb.triggers import ClockCycles, RisingEdge, SimTimeoutError, with_timeout
from cocotbext.axi import (
    AxiRamRead,
    AxiReadBus,
    AxiStreamBus,
    AxiStreamFrame,
    AxiStreamSink,
    AxiStreamSource,
)

import memory
from layout import Layout
from model import build_tree, check_result, check_tree

LAYOUT = Layout(os.environ["PHOTON_AXIS_DIR"])
CORE = LAYOUT.core
QUERIES = int(os.environ.get("PHOTON_AXIS_QUERIES", "1000"))
SEED = int(os.environ.get("PHOTON_AXIS_SEED", "1"))
WATCHDOG = 5000
PHOTON, QUERY, RESULT = LAYOUT["s_axis_photon"], LAYOUT["s_axis_query"], LAYOUT["m_axis_result"]
# The result streams' ports (a core of R result streams has R, each RESULT's layout).
RESULT_PORTS = CORE.get("result_ports", ["m_axis_result"])
# The external-memory core: its map's image in an AxiRamRead behind m_axi.
MEMORY = CORE.get("memory")
# PHOTON_AXIS_SWAP_BLOCKS=i,j: the bench's image has blocks i and j swapped (a
# broken layout, which the bench must reject).
SWAP_BLOCKS = tuple(int(b) for b in os.environ["PHOTON_AXIS_SWAP_BLOCKS"].split(",")) if os.environ.get("PHOTON_AXIS_SWAP_BLOCKS") else None


def pauses(rng, p):
    """A pause generator: paused with probability p, drawn anew each cycle."""
    while True:
        yield rng.random() < p


class Map:
    """A random photon map on the core's grid (with duplicates: ties) and its tree."""

    def __init__(self, rng, n):
        if MEMORY:  # the map reaches the memory (N >= 2^T, the export's rule)
            n = max(n, 1 << MEMORY["on_chip_levels"])
        maxes = [(1 << b) - 1 for b in CORE["coord_bits"]]
        pts = [[rng.randint(0, m) for m in maxes] for _ in range(n)]
        for _ in range(n // 10):  # a tenth are copies of another photon
            pts[rng.randrange(n)] = list(pts[rng.randrange(n)])
        self.points = pts
        self.coords, self.axis = build_tree(pts)
        check_tree(self.coords, self.axis)

    def frame(self):
        """The load: one packed word per heap address 1..N, in the documented layout."""
        data = b"".join(
            PHOTON.pack_bytes(x=c[0], y=c[1], z=c[2], axis=a)
            for c, a in zip(self.coords[1:], self.axis[1:])
        )
        if MEMORY:
            # The on-chip levels (padded beyond N), then a beat holding N.
            nb = PHOTON.tdata_bytes
            on_chip = (1 << MEMORY["on_chip_levels"]) - 1
            data = data[: on_chip * nb].ljust(on_chip * nb, b"\0")
            data += (len(self.coords) - 1).to_bytes(nb, "little")
        return AxiStreamFrame(data)

    def image(self):
        """The external memory's bytes for this map (memory.py)."""
        words = [b""] + [
            PHOTON.pack_bytes(x=c[0], y=c[1], z=c[2], axis=a)
            for c, a in zip(self.coords[1:], self.axis[1:])
        ]
        return memory.image(
            words, CORE["address_bits"], MEMORY["on_chip_levels"], MEMORY["block_levels"],
            MEMORY["word_bytes"], SWAP_BLOCKS,
        )


def random_queries(rng, m, count):
    maxes = [(1 << b) - 1 for b in CORE["coord_bits"]]
    max_dist = sum(maxes) if CORE["metric"] == "l1" else sum(x * x for x in maxes)
    qs = []
    for _ in range(count):
        if rng.random() < 0.2:  # on a photon: distance-0 ties
            q = [int(c) for c in m.coords[rng.randint(1, len(m.coords) - 1)]]
        else:
            q = [rng.randint(0, mx) for mx in maxes]
        r = rng.choice(
            [(1 << 32) - 1, max_dist, rng.randint(0, max_dist // 8), rng.randint(0, max_dist // 8)]
        )
        qs.append((q, rng.randint(1, CORE["k"]), r))
    return qs


class Bench:
    def __init__(self, dut, rng):
        self.dut = dut
        self.rng = rng
        self.photon = AxiStreamSource(
            AxiStreamBus.from_prefix(dut, "s_axis_photon"), dut.aclk, dut.aresetn,
            reset_active_level=False,
        )
        self.query = AxiStreamSource(
            AxiStreamBus.from_prefix(dut, "s_axis_query"), dut.aclk, dut.aresetn,
            reset_active_level=False,
        )
        self.results = [
            AxiStreamSink(
                AxiStreamBus.from_prefix(dut, port), dut.aclk, dut.aresetn,
                reset_active_level=False,
            )
            for port in RESULT_PORTS
        ]
        self.photon.set_pause_generator(pauses(random.Random(rng.random()), 0.3))
        self.query.set_pause_generator(pauses(random.Random(rng.random()), 0.3))
        for sink in self.results:
            sink.set_pause_generator(pauses(random.Random(rng.random()), 0.4))
        for end in (self.photon, self.query, *self.results):
            end.log.setLevel(logging.WARNING)  # not a line per frame
        self.ram = None
        if MEMORY:
            # Larger than any image the tests write (up to 2^H words).
            size = MEMORY["word_bytes"] << (CORE["address_bits"] + 1)
            self.ram = AxiRamRead(
                AxiReadBus.from_prefix(dut, "m_axi"), dut.aclk, dut.aresetn,
                reset_active_level=False, size=size,
            )
            self.ram.ar_channel.set_pause_generator(pauses(random.Random(rng.random()), 0.3))
            self.ram.r_channel.set_pause_generator(pauses(random.Random(rng.random()), 0.3))
            self.ram.log.setLevel(logging.WARNING)
        self.checked = 0
        # Packets received per result port.
        self.per_port = [0] * len(self.results)

    async def reset(self, cycles=4):
        self.dut.aresetn.value = 0
        self.query.clear()
        self.photon.clear()
        await ClockCycles(self.dut.aclk, cycles)
        self.dut.aresetn.value = 1
        await ClockCycles(self.dut.aclk, 2)
        for sink in self.results:
            sink.clear()

    def results_empty(self):
        return all(sink.empty() for sink in self.results)

    async def load(self, m, fresh=False):
        if self.ram is not None:
            # A new map in memory: reset first (unless just reset), write the image.
            if not fresh:
                await self.reset()
            self.ram.write(0, m.image())
        await self.photon.send(m.frame())
        await self.photon.wait()

    def receive(self, frame):
        """Split a result frame into its beats; check the packet's structure."""
        data = bytes(frame.tdata)
        nb = RESULT.tdata_bytes
        assert len(data) % nb == 0, f"result frame of {len(data)} bytes"
        beats = [RESULT.unpack(int.from_bytes(data[i : i + nb], "little")) for i in range(0, len(data), nb)]
        for i, b in enumerate(beats):
            word = int.from_bytes(data[i * nb : (i + 1) * nb], "little")
            assert word & RESULT.padding_mask() == 0, f"padding bits set: {word:#x}"
            assert b["last"] == (i == len(beats) - 1), f"last flag at beat {i} of {len(beats)}"
        head = beats[0]
        assert head["header"] == 1, "a packet must start with its header"
        found = []
        for b in beats[1:]:
            assert b["header"] == 0, "a header inside a packet"
            assert b["id"] == head["id"], "entries of another query inside a packet"
            found.append((b["address"], b["distance"]))
            if b["pair"]:
                found.append((b["address2"], b["distance2"]))
        assert len(found) == head["count"], f"{len(found)} photons, header count {head['count']}"
        return head["id"], found, head["visited"]

    async def run_queries(self, m, queries, tags, stop_after=None):
        """Stream `queries` (tags from `tags`, reused once their result is back) and
        check every result. With `stop_after`, return once that many results are
        checked, leaving the rest in flight."""
        free = list(tags)
        pending = {}
        sent = 0
        total = len(queries) if stop_after is None else stop_after
        received = 0

        async def sender():
            nonlocal sent
            for q in queries:
                while not free:
                    await RisingEdge(self.dut.aclk)
                tag = free.pop(0)
                pending[tag] = q
                (x, y, z), k, r = q
                await self.query.send(QUERY.pack_bytes(id=tag, x=x, y=y, z=z, radius=r, k=k))
                sent += 1

        async def receiver():
            nonlocal received
            while received < total:
                # A result within WATCHDOG cycles, or the core (or its tlast) is stuck.
                try:
                    frame = await with_timeout(frames.get(), WATCHDOG * 10, "ns")
                except SimTimeoutError:
                    raise AssertionError(
                        f"no result packet (tlast) for {WATCHDOG} cycles, {received} of {total} received"
                    ) from None
                tag, found, visited = self.receive(frame)
                assert tag in pending, f"result for tag {tag}, not in flight"
                q = pending.pop(tag)
                (x, y, z), k, r = q
                errors = check_result(m.coords, (x, y, z), k, r, CORE["metric"], found)
                assert not errors, f"query {q}: " + "; ".join(errors)
                assert visited >= 1, f"query {q}: visited {visited}"
                free.append(tag)
                received += 1
                self.checked += 1

        # Every result stream's packets into one queue, in the order they complete.
        async def forward(i, sink):
            while True:
                frame = await sink.recv()
                self.per_port[i] += 1
                await frames.put(frame)

        frames = Queue()
        forwarders = [cocotb.start_soon(forward(i, sink)) for i, sink in enumerate(self.results)]
        s = cocotb.start_soon(sender())
        await receiver()
        for f in forwarders:
            f.cancel()
        if stop_after is None:
            await s
        else:
            s.cancel()
        return pending


def tag_pool():
    return range(1 << CORE["id_bits"])


async def start(dut):
    rng = random.Random(SEED)
    Clock(dut.aclk, 10, unit="ns").start()
    bench = Bench(dut, rng)
    await bench.reset()
    return rng, bench


@cocotb.test()
async def one_map_many_queries(dut):
    """A random map through the photon stream, QUERIES random queries."""
    rng, bench = await start(dut)
    m = Map(rng, min(CORE["max_photons"], 300 + rng.randrange(100)))
    await bench.load(m, fresh=True)
    await bench.run_queries(m, random_queries(rng, m, QUERIES), tag_pool())
    # Every result stream carried packets (each serves its own datapaths).
    assert all(bench.per_port), f"packets per result port {bench.per_port}"
    dut._log.info("%d results checked against brute force, 0 mismatches (per result port: %s)",
                  bench.checked, bench.per_port)


@cocotb.test()
async def second_map_replaces_first(dut):
    """Two maps one after the other without reset (an external-memory core: with one,
    as its export says); each answers its own queries."""
    rng, bench = await start(dut)
    for i, n in enumerate((1 + rng.randrange(40), min(CORE["max_photons"], 200 + rng.randrange(200)))):
        m = Map(rng, n)
        await bench.load(m, fresh=i == 0)
        await bench.run_queries(m, random_queries(rng, m, max(50, QUERIES // 5)), tag_pool())
    dut._log.info("%d results checked against brute force, 0 mismatches", bench.checked)


@cocotb.test()
async def reset_mid_stream(dut):
    """aresetn asserted with queries in flight: after it, a reloaded map answers new
    queries correctly and no result of an aborted query ever leaves."""
    rng, bench = await start(dut)
    half = len(tag_pool()) // 2
    m = Map(rng, min(CORE["max_photons"], 250))
    await bench.load(m, fresh=True)
    qs = random_queries(rng, m, 400)
    aborted = await bench.run_queries(m, qs, range(half), stop_after=40)
    assert aborted, "no query was in flight at the reset"
    await bench.reset(cycles=3)
    m2 = Map(rng, min(CORE["max_photons"], 180))
    await bench.load(m2, fresh=True)
    # New queries use the other half of the tags: a result with an old tag after
    # the reset is an aborted query's and fails run_queries ("not in flight").
    await bench.run_queries(m2, random_queries(rng, m2, max(50, QUERIES // 5)), range(half, 2 * half))
    await ClockCycles(dut.aclk, 200)
    assert bench.results_empty(), "results left over after the last query"
    dut._log.info("%d results checked (%d queries pending at the reset, none answered after it)", bench.checked, len(aborted))
