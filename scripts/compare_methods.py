#!/usr/bin/env python3
"""Whole-image error against wall time: `photon-fpga render --method direct` (the
paper's direct visualization), `--method two-pass` (Jensen's two-pass method, each
final-gather ray a k-nearest lookup), `--method two-pass-irradiance` (the same with
Christensen's precomputed irradiance, each gather ray a 1-nearest lookup) and
Mitsuba 3's path tracer, each against the converged Mitsuba reference.

    cargo build --release
    venv/bin/pip install mitsuba==3.9.1 numpy matplotlib
    venv/bin/python scripts/compare_methods.py --threads 2 \
        --reference docs/reference/cornell_64.pfm --out docs/two_pass
    (and --reference docs/reference/cornell_128.pfm --out docs/two_pass_128)

writes OUT.md (the table), OUT.csv and OUT.png (error against time, the
non-dominated front drawn). Error: relative RMS error of linear RGB radiance over
the whole image, sqrt(sum (x - ref)^2 / sum ref^2); also over the pixels where the
reference does not see the light, directly or in the mirror, nor does a neighbour
(`light_mask`: the light's own pixels, ~30 to 60, weigh more than the rest of the
image together, and the error there is the antialiasing of its edges). Time: the
wall time of the whole `render` process (photon trace, kd-tree build, eye pass,
output) for photon-fpga, and of `mi.render` alone (scene loaded) for Mitsuba, on the
same threads.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_reference as ref  # noqa: E402


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            sys.exit(f"error: {path}: not a colour PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        a = np.frombuffer(f.read(), dtype=dtype).reshape(h, w, 3)
    return a[::-1].astype(np.float64)


def light_mask(reference):
    """True where the reference does not see the light (maximum channel below 5),
    nor does any of the pixel's 8 neighbours: a pixel the light's edge crosses is
    partly covered, and a few eye samples make it all light or none."""
    bright = reference.max(axis=2) >= 5.0
    grown = bright.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(bright, dy, axis=0), dx, axis=1)
    return ~grown


def errors(img, reference):
    full = np.sqrt(((img - reference) ** 2).sum() / (reference**2).sum())
    mask = light_mask(reference)[:, :, None]
    masked = np.sqrt((((img - reference) ** 2) * mask).sum() / ((reference**2) * mask).sum())
    return full, masked


def run_render(binary, size, threads, method, spp, rays, photons, seed):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "r.pfm")
        cmd = [binary, "render", "--size", f"{size}x{size}", "--spp", str(spp),
               "--photons", str(photons), "--threads", str(threads), "--seed", str(seed),
               "--method", method, "--out", out]
        if method.startswith("two-pass"):
            cmd += ["--gather-rays", str(rays)]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        return time.perf_counter() - t0, read_pfm(out)


def pareto(rows):
    """Indices of the rows no other row beats in both time and error."""
    keep = []
    for i, r in enumerate(rows):
        if not any(o["time"] <= r["time"] and o["error"] < r["error"] or
                   o["time"] < r["time"] and o["error"] <= r["error"] for o in rows):
            keep.append(i)
    return keep


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default="target/release/photon-fpga")
    ap.add_argument("--scene", default="scenes/cornell.toml")
    ap.add_argument("--reference", default="docs/reference/cornell_64.pfm")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", required=True, help="path prefix of the .md, .csv, .png")
    a = ap.parse_args()
    reference = read_pfm(a.reference)
    size = reference.shape[1]
    rows = []

    def add(method, setting, t, img):
        full, masked = errors(img, reference)
        rows.append(dict(method=method, setting=setting, time=t, error=full, masked=masked))
        print(f"{method:19} {setting:28} {t:7.2f} s  {full:.4f}  {masked:.4f}", flush=True)

    photons = 200_000
    # The same sample budgets per image at every size: 64x64 at the most samples per
    # pixel, fewer for larger images (time, and render's memory limit on the direct
    # method's gathered photons).
    fits = lambda spp, most: spp * size * size <= most * 64 * 64  # noqa: E731
    for spp in [s for s in [1, 4, 16, 64, 256, 1024] if fits(s, 1024)]:
        t, img = run_render(a.bin, size, a.threads, "direct", spp, 0, photons, 1)
        add("direct", f"spp {spp}, {photons} photons", t, img)
    two_pass = [(1, 4), (1, 16), (4, 4), (4, 16), (16, 4), (16, 16), (64, 4), (256, 4)]
    for method in ["two-pass", "two-pass-irradiance"]:
        for spp, rays in [(s, r) for s, r in two_pass if fits(s, 256)]:
            t, img = run_render(a.bin, size, a.threads, method, spp, rays, photons, 1)
            add(method, f"spp {spp}, {rays} rays, {photons} photons", t, img)
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mi.set_log_level(mi.LogLevel.Warn)
    import tomllib

    with open(a.scene, "rb") as f:
        scene = tomllib.load(f)
    for spp in [s for s in [4, 16, 64, 256, 1024, 4096] if fits(s, 4096)]:
        s = mi.load_dict(ref.scene_dict(mi, scene, (size, size), spp))
        t0 = time.perf_counter()
        img = np.array(mi.render(s, seed=987654, spp=spp), dtype=np.float64)[:, :, :3]
        add("mitsuba", f"path tracer, spp {spp}", time.perf_counter() - t0, img)

    # A point is on the front if no other is at least as fast and at least as good,
    # on either error.
    front = set(pareto(rows)) | set(
        pareto([dict(r, error=r["masked"]) for r in rows]))
    with open(a.out + ".csv", "w") as f:
        f.write("method,setting,seconds,rel_rmse,rel_rmse_without_light,front\n")
        for i, r in enumerate(rows):
            f.write(f"{r['method']},\"{r['setting']}\",{r['time']:.3f},{r['error']:.5f},"
                    f"{r['masked']:.5f},{int(i in front)}\n")
    with open(a.out + ".md", "w") as f:
        f.write(f"<!-- generated by scripts/compare_methods.py --threads {a.threads} "
                f"--reference {a.reference} --out {a.out}; edit the script, not this -->\n\n")
        f.write(f"Cornell box, {size}x{size}, {a.threads} threads, against "
                f"`{a.reference}` (Mitsuba 3 path tracer; scripts/mitsuba_reference.py).\n\n")
        f.write("| method | setting | wall s | rel. RMSE | without the light's pixels | "
                "non-dominated (either error) |\n|---|---|---:|---:|---:|---|\n")
        for i, r in enumerate(sorted(rows, key=lambda r: r["time"])):
            f.write(f"| {r['method']} | {r['setting']} | {r['time']:.2f} | {r['error']:.4f} | "
                    f"{r['masked']:.4f} | {'yes' if rows.index(r) in front else ''} |\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for method, marker in [("direct", "o"), ("two-pass", "s"), ("two-pass-irradiance", "D"),
                           ("mitsuba", "^")]:
        pts = sorted((r["time"], r["masked"]) for r in rows if r["method"] == method)
        ax.plot(*zip(*pts), marker=marker, label=method)
    masked_rows = [dict(r, error=r["masked"]) for r in rows]
    fr = sorted((masked_rows[i]["time"], masked_rows[i]["error"]) for i in pareto(masked_rows))
    ax.step(*zip(*fr), where="post", color="k", linestyle=":", label="non-dominated front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"wall time, s ({a.threads} threads)")
    ax.set_ylabel("rel. RMSE of linear radiance, without the light's pixels")
    ax.set_title(f"Cornell box {size}x{size} against a Mitsuba 3 reference")
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out + ".png", dpi=100)


if __name__ == "__main__":
    main()
