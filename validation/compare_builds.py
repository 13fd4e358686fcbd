#!/usr/bin/env python3
"""Are two builds' images bit-identical? For restructurings that must not change behaviour.

Renders every scene in scenes/ and validation/scenes/ (and the demo) with two `nebula`
binaries, on the CPU (or the GPU: --backend cuda), in every mode a user reaches from the
command line (exact, smooth, pyramid levels, the three camera kinds, drawn stars, the
axial marcher in each skip mode, the ground truth), and compares the pixels of each pair
of images byte for byte. Each binary gets its own table cache, so table generation is
compared as well.

    /usr/bin/python3 validation/compare_builds.py --old OLD/bin/nebula --new build/bin/nebula

Prints one line per case and exits 1 when any pair differs or any run fails.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "validation"))
from accuracy_report import write_densities  # noqa: E402  (the layer and wedge grids)

SMALL = ["--width", "96", "--height", "96"]


def cases(work):
    """(name, argv) pairs; argv after the binary, the output path appended as -o."""
    scenes = sorted(os.path.join(ROOT, "scenes", f) for f in os.listdir(os.path.join(ROOT, "scenes"))
                    if f.endswith(".toml"))
    validation = sorted(os.path.join(work, f) for f in os.listdir(work) if f.endswith(".toml"))
    out = [("--demo", ["render", "--demo"] + SMALL)]
    for s in scenes + validation:
        name = os.path.splitext(os.path.basename(s))[0]
        out.append((name, ["render", s] + SMALL))
    fig12 = os.path.join(ROOT, "scenes", "fig12_reference.toml")
    thin = os.path.join(work, "thin_nebula.toml")
    sphere = os.path.join(ROOT, "scenes", "uniform_sphere.toml")
    axial = os.path.join(ROOT, "scenes", "axial_bipolar.toml")
    out += [
        ("fig12 smooth 0.5", ["render", fig12, "--smooth", "0.5"] + SMALL),
        ("fig12 levels 2", ["render", fig12, "--levels", "2"] + SMALL),
        ("thin levels 3", ["render", thin, "--levels", "3"]),
        ("fig12 fisheye", ["render", fig12, "--set", "camera.kind=fisheye"] + SMALL),
        ("fig12 drawn stars", ["render", fig12, "--set", "output.draw_stars=true"] + SMALL),
        ("fig12 albedo/g per band, R_V 3.1, odonnell94",
         ["render", fig12, "--set", "dust.albedo={B = 0.7, V = 0.6, R = 0.5}", "--set", "dust.g={B = 0.6, V = 0.6, R = 0.3}",
          "--set", "dust.R_V=3.1", "--set", "dust.law=odonnell94"] + SMALL),
        ("sphere V only, a=0", ["render", sphere, "--set", "bands=[\"V\"]", "--set", "dust.albedo=0"] + SMALL),
        ("thin truth", ["truth", thin, "--spp", "4", "--width", "32", "--height", "32"]),
        ("thin truth equiangular exact", ["truth", thin, "--spp", "4", "--width", "24", "--height", "24",
                                          "--equiangular", "--transmittance", "exact"]),
    ]
    for skip in ["naive", "empty", "global_max", "omega", "omega_multi", "distance"]:
        out.append((f"axial {skip}", ["render", axial, "--set", f"axial.skip={skip}", "--set", "axial.nx=128",
                                      "--set", "axial.nr=64"] + SMALL))
    out.append(("axial orthographic", ["render", axial, "--set", "camera.kind=orthographic", "--set",
                                       "camera.ortho_width=3", "--set", "axial.nx=128", "--set", "axial.nr=64"] + SMALL))
    return out


def run(binary, argv, path, cache, cwd, backend):
    env = dict(os.environ, NEBULA_CACHE_DIR=cache)
    cmd = [binary] + argv + ["--backend", backend, "-q", "--force", "-o", path]
    if argv[0] == "render":
        cmd += ["--table-photons", "3000"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()}")


def datasets(path):
    with h5py.File(path, "r") as f:
        out = {}
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        return out


def identical(a, b):
    da, db = datasets(a), datasets(b)
    if da.keys() != db.keys():
        return f"datasets differ: {sorted(da)} against {sorted(db)}"
    for k in da:
        x, y = np.asarray(da[k]), np.asarray(db[k])
        if x.shape != y.shape or x.dtype != y.dtype:
            return f"{k}: {x.shape} {x.dtype} against {y.shape} {y.dtype}"
        if x.tobytes() != y.tobytes():
            diff = np.abs(x.astype(np.float64) - y.astype(np.float64))
            return f"{k}: {np.count_nonzero(diff)} of {diff.size} values differ, largest by {diff.max():.3g}"
    return ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", required=True, help="the reference build's nebula binary")
    ap.add_argument("--new", required=True, help="the build under test")
    ap.add_argument("--work", help="scratch folder (default: a temporary one, removed after)")
    ap.add_argument("--backend", default="cpu", choices=["cpu", "cuda"], help="where both builds render")
    args = ap.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="nebula-compare-")
    os.makedirs(work, exist_ok=True)
    for f in os.listdir(os.path.join(ROOT, "validation", "scenes")):
        shutil.copy(os.path.join(ROOT, "validation", "scenes", f), work)
    write_densities(work)
    failures = 0
    start = time.time()
    all_cases = cases(work)
    for k, (name, argv) in enumerate(all_cases):
        outs = []
        try:
            for tag, binary in (("old", args.old), ("new", args.new)):
                path = os.path.join(work, f"case{k}_{tag}.h5")
                run(os.path.abspath(binary), argv, path, os.path.join(work, "cache_" + tag), work, args.backend)
                outs.append(path)
            verdict = identical(*outs)
            if argv[0] == "truth" and not verdict:
                verdict = identical(*[p[:-3] + ".var.h5" for p in outs])
        except RuntimeError as e:
            verdict = str(e)
        failures += bool(verdict)
        print(f"{'identical' if not verdict else 'DIFFERENT'}  {name}{'' if not verdict else ': ' + verdict}", flush=True)
    print(f"{len(all_cases) - failures} of {len(all_cases)} cases bit-identical ({time.time() - start:.0f} s)")
    if not args.work:
        shutil.rmtree(work)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
