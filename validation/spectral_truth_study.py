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
import os
import re
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "validation"))
from nebula_runner import Runner, prepare_work, read_rows, study_arguments, truth_grid, write_rows  # noqa: E402

SCENES = ["fig12_reference", "sphere_tau1", "sphere_tau5"]
FILTERS = {"n450": 450, "n550": 550, "n700": 700}
NOISY = 0.005  # a bias whose standard error is this or more is shown with it
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
    ap = study_arguments(__doc__.split("\n")[0], "/tmp/nebula-spectral-truth", "docs/spectral_truth.md", SCENES)
    ap.add_argument("--note", default="", help="a paragraph for the page, under its header")
    ap.add_argument("--merge", default="", help="comma-separated JSON rows of earlier runs (e.g. one per group of "
                    "scenes at its own --spp, each within a device call's time): write the page from them, render "
                    "nothing")
    args = ap.parse_args()
    if args.truth_strata < 1:
        raise SystemExit(f"--truth-strata: must be 1 or more, got {args.truth_strata}")
    if args.merge:
        return merge(args)
    prepare_work(args)
    r = Runner(args)
    albedos = [float(a) for a in args.albedos.split(",")]
    gs = [float(g) for g in args.gs.split(",")]
    rows = []
    start = time.time()
    for scene in args.scenes.split(","):
        paths = write_scenes(args.work, scene)
        for a, g, shared, tag, truth, truth_seconds in truth_grid(r, args, scene, paths["band"]):
            for method, (kind, extra) in METHODS.items():
                out = os.path.join(args.work, f"{kind}_{tag}_{len(extra)}.h5")
                t0 = time.time()
                r.run(["render", paths[kind], "--backend", r.backend, "-q", "--force", "-o", out] + shared + extra)
                seconds = time.time() - t0
                bands = r.compare(out, truth)
                row = dict(scene=scene, albedo=a, g=g, method=method, seconds=seconds, truth_seconds=truth_seconds,
                           bias=[b["bias"] for b in bands], bias_stderr=[b["bias_stderr"] for b in bands],
                           excess=[b["rel_l2_excess"] for b in bands], noise=[b["noise_rel_l2"] for b in bands],
                           spp=args.spp, truth_strata=args.truth_strata)
                rows.append(row)
                print(f"{scene:16s} a {a} g {g} {method:30s} bias " +
                      " ".join(f"{100 * x:+6.1f}%" for x in row["bias"]) + "  excess L2 " +
                      " ".join(f"{x:.3f}" for x in row["excess"]), flush=True)
    write_rows(rows, args.out)
    write_page(rows, args, albedos, gs, time.time() - start)


def merge(args):
    rows = read_rows(args.merge.split(","), METHODS)
    albedos = sorted({r["albedo"] for r in rows})
    gs = sorted({r["g"] for r in rows})
    truths = {(r["scene"], r["albedo"], r["g"]): r["truth_seconds"] for r in rows}
    write_rows(rows, args.out)
    write_page(rows, args, albedos, gs, sum(r["seconds"] for r in rows) + sum(truths.values()))


def write_page(rows, args, albedos, gs, elapsed):
    names = list(FILTERS)
    spp = {}
    for r in rows:
        spp.setdefault(r.get("spp", args.spp), []).append(r["scene"])
    side = sorted({r.get("truth_strata", 1) for r in rows})
    flags = f" --truth-strata {side[0]}" if side != [1] and len(side) == 1 else ""
    if len(spp) == 1:
        runs = f"--spp {next(iter(spp))}{flags} --out {args.out}`"
        truth_spp = f"--spp {next(iter(spp))}`"
    else:  # groups of scenes run apart, then --merge
        groups = "; ".join(f"`--spp {n}{flags} --scenes {','.join(dict.fromkeys(v))} --out PART.md`"
                           for n, v in spp.items())
        runs = f"--out PART.md` per group of scenes ({groups}), then `--merge` of the parts' JSON"
        truth_spp = "--spp N`, N per group as above,"
    strata = "" if side == [1] else (" with " + " or ".join(f"{k} x {k}" for k in side) +
                                     " pixel-area strata (`--truth-strata`; render.samples_per_pixel for the truth),")
    out = ["<!-- Generated by validation/spectral_truth_study.py; edit the script, not this page. -->",
           "# The spectral renderer's light between voxels against the truth\n",
           f"Regenerate: `/usr/bin/python3 validation/spectral_truth_study.py --backend {args.backend} "
           f"{runs} ({elapsed / 60:.1f} min of renders{', ' + args.machine if args.machine else ''}). "
           f"The truth: `nebula truth --equiangular {truth_spp}{strata} through three top-hat filters 10 nm wide at "
           "450, 550 and 700 nm (narrow enough for the truth's one attenuation and star power per band to be the "
           f"spectral answer); the Fig. 12 scene at {args.fig12_pixels}x{args.fig12_pixels} pixels, the others at "
           "their own 64x64. Each cell: the bias Σ(render − truth)/Σtruth over pixels with signal in the three "
           "filters, then (in brackets) the largest of their L2 errors beyond the truth's noise. The method: "
           "[spectral.md](spectral.md), \"Light between voxels\". A bias the truth leaves uncertain by "
           f"{100 * NOISY:g}% or more is followed by its standard error (± σ; the truth's samples are heavy-tailed "
           "near a star).\n"]
    if args.note:
        out.append(args.note + "\n")
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
                    cells.append(" / ".join(f"{100 * b:+.1f}%" + (f" ± {100 * e:.1f}%" if e >= NOISY else "")
                                            for b, e in zip(sel[0]["bias"], sel[0]["bias_stderr"])) +
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
