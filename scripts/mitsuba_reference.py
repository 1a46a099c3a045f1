#!/usr/bin/env python3
"""A converged reference of a photon-fpga scene from an independent renderer:
Mitsuba 3's path tracer, the scene converted from the project's TOML.

    python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
    venv/bin/python scripts/mitsuba_reference.py [--scene scenes/cornell.toml] \
        [--size 64] [--spp 16384] --out docs/reference/cornell_64.pfm
    (docs/reference/cornell_128.pfm: --size 128)

writes linear RGB radiance as a PFM (the format of `photon-fpga render --out X.pfm`).

The conversion, and why each choice matches the project's renderer
(src/host/render/geometry.rs, photons.rs):
* quads: Mitsuba `rectangle`s (the square [-1, 1]^2 at z = 0) placed by the affine
  map with columns edge_u/2, edge_v/2, the unit normal, and the centre; diffuse
  ones `twosided`, since the project's diffuse surfaces reflect on both faces;
* spheres: `sphere`s; `mirror` -> a perfect `conductor` (material none, reflectance
  1), `glass` -> `dielectric` with the scene's ior against vacuum;
* the light: a `rectangle` with an `area` emitter of radiance power / (pi A) on the
  side of normalize(edge_u x edge_v) (a one-sided Lambertian emitter of flux
  `power`) and a black BSDF (the project's light absorbs whatever hits it);
* camera: `perspective`, vertical `fov_deg` (fov_axis y), look_at; a `box` pixel
  filter, as the project's eye rays are jittered uniformly over each pixel;
* integrator: `path` with unbounded depth (Russian roulette from depth 5).
"""

import argparse
import math
import sys
import tomllib

import numpy as np


def parallelogram(mi, corner, edge_u, edge_v):
    c = np.array(corner, float)
    u = np.array(edge_u, float)
    v = np.array(edge_v, float)
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    centre = c + 0.5 * u + 0.5 * v
    m = np.identity(4)
    m[:3, 0] = 0.5 * u
    m[:3, 1] = 0.5 * v
    m[:3, 2] = n
    m[:3, 3] = centre
    return mi.ScalarTransform4f(m.tolist()), float(np.linalg.norm(np.cross(u, v)))


def bsdf_of(material):
    kind = material["type"]
    if kind == "diffuse":
        rgb = [float(x) for x in material["rgb"]]
        return {
            "type": "twosided",
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}},
        }
    if kind == "mirror":
        return {"type": "conductor", "material": "none"}
    if kind == "glass":
        return {"type": "dielectric", "int_ior": float(material["ior"]), "ext_ior": 1.0}
    sys.exit(f"error: unknown material type {kind!r}")


def scene_dict(mi, scene, size, spp):
    cam = scene["camera"]
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": float(cam["fov_deg"]),
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[float(x) for x in cam["position"]],
                target=[float(x) for x in cam["look_at"]],
                up=[float(x) for x in cam["up"]],
            ),
            "film": {
                "type": "hdrfilm",
                "width": size[0],
                "height": size[1],
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    materials = scene["materials"]
    for i, q in enumerate(scene.get("quad", [])):
        to_world, _ = parallelogram(mi, q["corner"], q["edge_u"], q["edge_v"])
        d[f"quad{i}"] = {
            "type": "rectangle",
            "to_world": to_world,
            "bsdf": bsdf_of(materials[q["material"]]),
        }
    for i, s in enumerate(scene.get("sphere", [])):
        d[f"sphere{i}"] = {
            "type": "sphere",
            "center": [float(x) for x in s["center"]],
            "radius": float(s["radius"]),
            "bsdf": bsdf_of(materials[s["material"]]),
        }
    light = scene["light"]
    to_world, area = parallelogram(mi, light["corner"], light["edge_u"], light["edge_v"])
    radiance = [float(p) / (math.pi * area) for p in light["power"]]
    d["light"] = {
        "type": "rectangle",
        "to_world": to_world,
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}},
        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance}},
    }
    return d


def write_pfm(path, img):
    """img: (height, width, 3) float, rows from the top."""
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="scenes/cornell.toml")
    ap.add_argument("--size", type=int, default=64, help="width = height in pixels")
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant(a.variant)
    with open(a.scene, "rb") as f:
        scene = tomllib.load(f)
    # Rendered in passes of at most 1024 samples, averaged (bounded memory).
    passes = max(1, a.spp // 1024)
    per = a.spp // passes
    s = mi.load_dict(scene_dict(mi, scene, (a.size, a.size), per))
    acc = None
    for p in range(passes):
        img = np.array(mi.render(s, seed=a.seed * 100003 + p, spp=per), dtype=np.float64)
        acc = img if acc is None else acc + img
    write_pfm(a.out, (acc / passes)[:, :, :3])
    print(f"wrote {a.out}: {a.size}x{a.size}, {passes * per} spp, variant {mi.variant()}")


if __name__ == "__main__":
    main()
