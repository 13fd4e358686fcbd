#!/usr/bin/env python3
"""The spectral renderer with the light between voxels against the ground truth.

The truth (`nebula truth --equiangular`) takes one extinction ratio and one star power per
band: exact for a filter narrow enough that the dust's attenuation and the star's spectrum
do not change across it. So the scenes are seen through three filters 10 nm wide, at 450,
550 and 700 nm (top hats, written here), where the truth is the spectral answer; the
spectral renderer (its default: the projection with 4 basis elements, the voxels' tables
read at 3 attenuations, the diffuse field baked at those attenuations) integrates over
each filter. For every scene, albedo and g: the bias Sigma(spectral - truth)/Sigma truth
per filter over pixels with signal, the L2 error beyond the truth's noise, the same for
the spectral renderer without the light between voxels and for the band renderer (its
diffuse field baked at each filter's own attenuation), and the albedo's effect.

    /usr/bin/python3 validation/spectral_truth_study.py --nebula build/bin/nebula \\
        --backend cuda --spp 512 --out docs/spectral_truth.md

Writes the Markdown page (--out), the rows as JSON beside it, and prints each row.
"""
import argparse
import json
import os
import re
import shutil
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "validation"))
from nebula_runner import Runner  # noqa: E402

SCENES = ["fig12_reference", "sphere_tau1", "sphere_tau5"]
FILTERS = {"n450": 450, "n550": 550, "n700": 700}
METHODS = {
    "spectral (default)": ("spectral", []),
    "spectral, none between voxels": ("spectral", ["--set", "render.multiple_scattering=none"]),
    "band renderer (default)": ("band", []),
}


def write_scenes(work, name):
    """The scene with the narrow filters as its bands (band.toml) and with [spectral] too (spectral.toml)."""
    src = os.path.join(ROOT, "scenes", name + ".toml") if name == "fig12_reference" else \
        os.path.join(work, name + ".toml")
    text = open(src).read()
    text = re.sub(r"(?m)^bands\s*=.*$", "", text)
    for f, nm in FILTERS.items():
        with open(os.path.join(work, f + ".txt"), "w") as out:
            out.write(f"# a top hat 10 nm wide at {nm} nm\n{nm - 6} 0\n{nm - 5} 1\n{nm + 5} 1\n{nm + 6} 0\n")
    bands = "bands = [" + ", ".join(f'"{f}"' for f in FILTERS) + "]\n"
    filters = "\n[filters]\n" + "".join(f'{f} = "{f}.txt"\n' for f in FILTERS)
    paths = {}
    for kind, extra in (("band", ""), ("spectral", '\n[spectral]\nmethod = "projection"\nbasis = 4\n')):
        paths[kind] = os.path.join(work, f"{name}_{kind}.toml")
        with open(paths[kind], "w") as out:
            out.write(bands + text + filters + extra)
    return paths


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nebula", default=os.path.join(ROOT, "build", "bin", "nebula"))
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--work", default="/tmp/nebula-spectral-truth")
    ap.add_argument("--spp", type=int, default=512, help="truth samples per pixel")
    ap.add_argument("--fig12-pixels", type=int, default=128, help="image size of the Fig. 12 scene")
    ap.add_argument("--albedos", default="0.3,0.6,0.9")
    ap.add_argument("--gs", default="0,0.6,0.9")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--out", default="docs/spectral_truth.md")
    ap.add_argument("--machine", default="", help="the machine, for the page")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    for f in os.listdir(os.path.join(ROOT, "validation", "scenes")):
        shutil.copy(os.path.join(ROOT, "validation", "scenes", f), args.work)
    if any(s.startswith(("layer", "wedge")) for s in args.scenes.split(",")):
        from accuracy_report import write_densities  # the layer and wedge grids (numpy, h5py)
        write_densities(args.work)
    r = Runner(args)
    albedos = [float(a) for a in args.albedos.split(",")]
    gs = [float(g) for g in args.gs.split(",")]
    rows = []
    start = time.time()
    for scene in args.scenes.split(","):
        paths = write_scenes(args.work, scene)
        size = ["--width", str(args.fig12_pixels), "--height", str(args.fig12_pixels)] if scene == "fig12_reference" \
            else []
        for a in albedos:
            for g in gs:
                dust = ["--set", f"dust.albedo={a}", "--set", f"dust.g={g}"]
                tag = f"{scene}_a{a}_g{g}"
                truth = os.path.join(args.work, f"truth_{tag}.h5")
                t0 = time.time()
                r.run(["truth", paths["band"], "--spp", str(args.spp), "--equiangular", "--backend", r.backend, "-q",
                       "--force", "-o", truth] + size + dust)
                truth_seconds = time.time() - t0
                for method, (kind, extra) in METHODS.items():
                    out = os.path.join(args.work, f"{kind}_{tag}_{len(extra)}.h5")
                    t0 = time.time()
                    r.run(["render", paths[kind], "--backend", r.backend, "-q", "--force", "-o", out] + size + dust +
                          extra)
                    seconds = time.time() - t0
                    bands = r.compare(out, truth)
                    row = dict(scene=scene, albedo=a, g=g, method=method, seconds=seconds, truth_seconds=truth_seconds,
                               bias=[b["bias"] for b in bands], bias_stderr=[b["bias_stderr"] for b in bands],
                               excess=[b["rel_l2_excess"] for b in bands], noise=[b["noise_rel_l2"] for b in bands])
                    rows.append(row)
                    print(f"{scene:16s} a {a} g {g} {method:30s} bias " +
                          " ".join(f"{100 * x:+6.1f}%" for x in row["bias"]) + "  excess L2 " +
                          " ".join(f"{x:.3f}" for x in row["excess"]), flush=True)
    with open(args.out + ".json.tmp", "w") as f:
        json.dump(rows, f, indent=1)
    os.replace(args.out + ".json.tmp", os.path.splitext(args.out)[0] + ".json")
    write_page(rows, args, albedos, gs, time.time() - start)


def write_page(rows, args, albedos, gs, elapsed):
    names = list(FILTERS)
    out = ["<!-- Generated by validation/spectral_truth_study.py; edit the script, not this page. -->",
           "# The spectral renderer's light between voxels against the truth\n",
           f"Regenerate: `/usr/bin/python3 validation/spectral_truth_study.py --backend {args.backend} "
           f"--spp {args.spp} --out {args.out}` ({elapsed / 60:.1f} min{', ' + args.machine if args.machine else ''}). "
           f"The truth: `nebula truth --equiangular --spp {args.spp}` through three top-hat filters 10 nm wide at "
           "450, 550 and 700 nm (narrow enough for the truth's one attenuation and star power per band to be the "
           f"spectral answer); the Fig. 12 scene at {args.fig12_pixels}x{args.fig12_pixels} pixels, the others at "
           "their own 64x64. Each cell: the bias Σ(render − truth)/Σtruth over pixels with signal in the three "
           "filters, then (in brackets) the largest of their L2 errors beyond the truth's noise. The method: "
           "[spectral.md](spectral.md), \"Light between voxels\".\n"]
    scenes = list(dict.fromkeys(x["scene"] for x in rows))
    for method in METHODS:
        out.append(f"## {method}\n")
        out.append("| scene | g | " + " | ".join(f"a = {a}" for a in albedos) + " |")
        out.append("|---|---|" + "---|" * len(albedos))
        for scene in scenes:
            for g in gs:
                cells = []
                for a in albedos:
                    sel = [x for x in rows if x["scene"] == scene and x["g"] == g and x["albedo"] == a and
                           x["method"] == method]
                    cells.append(" / ".join(f"{100 * b:+.1f}%" for b in sel[0]["bias"]) +
                                 f" ({max(sel[0]['excess']):.3f})" if sel else "—")
                out.append(f"| {scene} | {g:g} | " + " | ".join(cells) + " |")
        out.append("")
    if len(albedos) >= 2:
        lo, hi = min(albedos), max(albedos)
        out.append(f"## The albedo's effect: brightness at a = {hi:g} over a = {lo:g}, render ÷ truth, per filter\n")
        out.append("| scene | g | " + " | ".join(METHODS) + " |")
        out.append("|---|---|" + "---|" * len(METHODS))
        for scene in scenes:
            for g in gs:
                cells = []
                for method in METHODS:
                    sel = {x["albedo"]: x for x in rows if x["scene"] == scene and x["g"] == g and x["method"] == method}
                    cells.append(" / ".join(f"{(1 + h) / (1 + l):.3f}" for h, l in zip(sel[hi]["bias"], sel[lo]["bias"]))
                                 if lo in sel and hi in sel else "—")
                out.append(f"| {scene} | {g:g} | " + " | ".join(cells) + " |")
        out.append("")
    out.append("Filters in each cell: " + ", ".join(names) + ".\n")
    with open(args.out + ".tmp", "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(args.out + ".tmp", args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
