#!/usr/bin/env python3
"""The fast renderer's multiple scattering against the ground truth, over albedo and g.

For every scene (the Fig. 12 reference, the five validation scenes, uniform spheres of
radial optical depth 1 and 5, and two axial maps lit by a star on their axis), every albedo a and every Henyey-Greenstein g, renders the
truth (`nebula truth --equiangular`) and the fast renderer in each way of adding the light
scattered between voxels (the diffuse field, the default; the 2005 pyramid with 1 to 3
levels; none), and writes per method a table of the bias Sigma(fast - truth)/Sigma truth
(V band, over pixels with signal) with the L2 error beyond the truth's noise, and the
albedo's effect: the brightness ratio between the largest and the smallest albedo, fast
against truth.

    /usr/bin/python3 validation/multiple_scattering_study.py --nebula build/bin/nebula \
        --backend cuda --spp 512 --out docs/multiple_scattering.md

Writes the Markdown page (--out), the rows as JSON beside it, and prints each row.
"""
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "validation"))
from nebula_runner import Runner, prepare_work, read_rows, study_arguments, truth_grid, write_rows  # noqa: E402

SCENES = ["fig12_reference", "thin_nebula", "thick_nebula", "layer_front", "layer_behind", "wedge", "sphere_tau1",
          "sphere_tau5", "axial_lopsided", "axial_lopsided_thick"]
METHODS = {
    "diffuse (default)": [],
    "diffuse taper none": ["--set", "render.diffuse_taper=none"],
    "diffuse taper lanczos": ["--set", "render.diffuse_taper=lanczos"],
    "diffuse harmonics only": ["--set", "render.diffuse_zonal=0"],
    "diffuse zonal 24 at every g": ["--set", "render.diffuse_zonal=24"],
    "diffuse degree 3": ["--set", "render.diffuse_order=3"],
    "pyramid 1 level": ["--levels", "1"],
    "pyramid 2 levels": ["--levels", "2"],
    "pyramid 3 levels": ["--levels", "3"],
    "none": ["--set", "render.multiple_scattering=none"],
}


def scene_path(work, name):
    if name == "fig12_reference":
        return os.path.join(ROOT, "scenes", name + ".toml")
    return os.path.join(work, name + ".toml")


def main():
    ap = study_arguments(__doc__.split("\n")[0], "/tmp/nebula-ms-study", "docs/multiple_scattering.md", SCENES)
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--note", default="", help="a paragraph for the page, under its header (what the merged runs "
                    "differ in, for example)")
    ap.add_argument("--merge", default="", help="comma-separated JSON rows of earlier runs (e.g. one per group of "
                    "scenes, each within a device call's time): write the page from them, render nothing")
    args = ap.parse_args()
    if args.truth_strata < 1:
        raise SystemExit(f"--truth-strata: must be 1 or more, got {args.truth_strata}")
    if args.merge:
        return merge(args)
    prepare_work(args)
    r = Runner(args)
    albedos = [float(a) for a in args.albedos.split(",")]
    gs = [float(g) for g in args.gs.split(",")]
    methods = [m for m in args.methods.split(",")]
    rows = []
    start = time.time()
    for scene in args.scenes.split(","):
        path = scene_path(args.work, scene)
        for a, g, shared, tag, truth, truth_seconds in truth_grid(r, args, scene, path):
            for method in methods:
                if scene.startswith("axial") and method.startswith("pyramid"):
                    continue  # the pyramid is built from 3D grids; axial maps refuse it
                out = fast_file(args.work, tag, method)
                t0 = time.time()
                r.run(["render", path, "--backend", r.backend, "-q", "--force", "-o", out] + shared + METHODS[method])
                seconds = time.time() - t0
                bands = r.compare(out, truth)
                v = [b for b in bands if b["band"] == "V"][0]
                row = dict(scene=scene, albedo=a, g=g, method=method, bias=v["bias"], bias_stderr=v["bias_stderr"],
                           excess=v["rel_l2_excess"], worst_1pct=v["worst_1pct"], noise=v["noise_rel_l2"],
                           bias_bands=[b["bias"] for b in bands], seconds=seconds, truth_seconds=truth_seconds,
                           spp=args.spp, truth_strata=args.truth_strata)
                rows.append(row)
                print(f"{scene:16s} a {a} g {g} {method:18s} bias {100 * row['bias']:+6.1f}% "
                      f"+- {100 * row['bias_stderr']:.1f}%  excess L2 {row['excess']:.3f}", flush=True)
    write_rows(rows, args.out)
    write_page(rows, args, albedos, gs, methods, time.time() - start)


def fast_file(work, tag, method):
    return os.path.join(work, f"fast_{tag}_{method.split()[0]}{method.split()[-1]}.h5")


def pixel_error(fast, truth):
    """The median over the pixels with signal (V band, as the bias) whose truth is known to 5% (its standard error) of
    |fast / truth - 1|: an error per pixel that, unlike the total bias and the L2 error, every such pixel weighs
    alike, the dim ones as much as those next to the star; the rim of the dust's image left out. None when a file
    is missing."""
    import h5py  # noqa: E402 (only at --merge, where the images are)
    import numpy as np

    paths = (fast, truth, truth[:-3] + ".var.h5")
    if not all(os.path.isfile(p) for p in paths):
        return None
    planes = []
    for p in paths:
        with h5py.File(p, "r") as f:
            names = [n.decode() if isinstance(n, bytes) else str(n) for n in f.attrs.get("bands", [b"V"])]
            image = np.asarray(f["image"], dtype=float)
            planes.append(image[names.index("V") if "V" in names else 0])
    F, T, var = planes
    # Not the pixels on the rim of the fast image's dust (nothing there or beside): the fast renderer's one ray
    # per pixel meets the grid or misses it where the truth's pixel-area strata cover part of the pixel.
    lit = F > 0
    inner = lit.copy()
    inner[1:, :] &= lit[:-1, :]
    inner[:-1, :] &= lit[1:, :]
    inner[:, 1:] &= lit[:, :-1]
    inner[:, :-1] &= lit[:, 1:]
    known = inner & (T > 1e-3 * T.max()) & (np.sqrt(np.maximum(var, 0)) < 0.05 * T)
    return float(np.median(np.abs(F[known] / T[known] - 1))) if known.any() else None


NOISY = 0.005  # a bias whose standard error is this or more is shown with it


def noisy(stderr):
    """' ± σ' for a bias the truth leaves uncertain by NOISY or more, else nothing."""
    return f" ± {100 * stderr:.1f}%" if stderr >= NOISY else ""


def merge(args):
    rows = read_rows(args.merge.split(","), METHODS)  # methods the study no longer has stay out
    for r in rows:  # the per-pixel error, from the images where the work folder holds them
        tag = f"{r['scene']}_a{r['albedo']}_g{r['g']}"
        e = pixel_error(fast_file(args.work, tag, r["method"]), os.path.join(args.work, f"truth_{tag}.h5"))
        if e is not None:
            r["pixel_error"] = e
    methods = [m for m in METHODS if any(r["method"] == m for r in rows)]
    albedos = sorted({r["albedo"] for r in rows})
    gs = sorted({r["g"] for r in rows})
    # The renders' time: every fast render, each truth once.
    truths = {(r["scene"], r["albedo"], r["g"]): r["truth_seconds"] for r in rows}
    elapsed = sum(r["seconds"] for r in rows) + sum(truths.values())
    write_rows(rows, args.out)
    write_page(rows, args, albedos, gs, methods, elapsed)


def write_page(rows, args, albedos, gs, methods, elapsed):
    spp = {}
    for r in rows:
        spp.setdefault(r.get("spp", args.spp), []).append(r["scene"])
    if len(spp) == 1:
        runs = f"--spp {next(iter(spp))} --out {args.out}`"
        truth_spp = f"--spp {next(iter(spp))}`"
    else:  # groups of scenes run apart, then --merge
        groups = "; ".join(f"`--spp {n} --scenes {','.join(dict.fromkeys(v))} --out PART.md`" for n, v in spp.items())
        runs = f"--out PART.md` per group of scenes ({groups}), then `--merge` of the parts' JSON"
        truth_spp = "--spp N`, N per group as above"
    sides = sorted({r.get("truth_strata", 1) for r in rows})
    strata = "" if sides == [1] else (", with " + " or ".join(f"{k} x {k}" for k in sides) +
                                      " pixel-area strata (`--truth-strata`; 1 x 1: the pixel's centre ray)")
    out = ["<!-- Generated by validation/multiple_scattering_study.py; edit the script, not this page. -->",
           "# Multiple scattering between voxels: the fast renderer against the truth\n",
           f"Regenerate: `/usr/bin/python3 validation/multiple_scattering_study.py --backend {args.backend} "
           f"{runs} ({elapsed / 60:.1f} min of renders{', ' + args.machine if args.machine else ''}). "
           f"The truth: `nebula truth --equiangular {truth_spp}{strata}; the Fig. 12 scene at "
           f"{args.fig12_pixels}x{args.fig12_pixels} pixels, the others at their own 64x64. Each cell: the V-band "
           "bias Σ(fast − truth)/Σtruth over pixels with signal, then (in brackets) the L2 error beyond the truth's "
           "noise" + ("" if not any("pixel_error" in r for r in rows) else
                      " and the median per-pixel error |fast/truth − 1| over the pixels with signal whose truth is "
                      "known to 5%, but for the rim of the dust's image, where one ray per pixel meets or misses the "
                      "grid (every such pixel weighs alike; it includes the truth's own noise)") +
           f". Where the truth leaves the bias uncertain by {100 * NOISY:g}% or more, its standard error follows it "
           "(± σ): the truth's samples are heavy-tailed near a star (a path scattered close to it), so one pixel can "
           "carry most of a total's uncertainty. The method is [docs/diffuse.md](diffuse.md).\n"]
    if args.note:
        out.append(args.note + "\n")
    scenes = list(dict.fromkeys(x["scene"] for x in rows))
    for method in methods:
        out.append(f"## {method}\n")
        out.append("| scene | g | " + " | ".join(f"a = {a}" for a in albedos) + " |")
        out.append("|---|---|" + "---|" * len(albedos))
        for scene in scenes:
            for g in gs:
                cells = []
                for a in albedos:
                    sel = [x for x in rows if x["scene"] == scene and x["g"] == g and x["albedo"] == a and
                           x["method"] == method]
                    pixel = f"; {100 * sel[0]['pixel_error']:.1f}%" if sel and "pixel_error" in sel[0] else ""
                    cells.append(f"{100 * sel[0]['bias']:+.1f}%{noisy(sel[0]['bias_stderr'])} "
                                 f"({sel[0]['excess']:.3f}{pixel})" if sel else "—")
                if any(c != "—" for c in cells):  # axial maps have no pyramid rows
                    out.append(f"| {scene} | {g:g} | " + " | ".join(cells) + " |")
        out.append("")
    if len(albedos) >= 2:
        lo, hi = min(albedos), max(albedos)
        out.append(f"## The albedo's effect: brightness at a = {hi:g} over a = {lo:g}, fast ÷ truth\n")
        out.append("Each cell: (1 + bias at a = %g) / (1 + bias at a = %g); 1 means the fast renderer shows the "
                   "albedo's effect as strongly as the truth.\n" % (hi, lo))
        out.append("| scene | g | " + " | ".join(methods) + " |")
        out.append("|---|---|" + "---|" * len(methods))
        for scene in scenes:
            for g in gs:
                cells = []
                for method in methods:
                    sel = {x["albedo"]: x for x in rows if x["scene"] == scene and x["g"] == g and x["method"] == method}
                    cells.append(f"{(1 + sel[hi]['bias']) / (1 + sel[lo]['bias']):.3f}" if lo in sel and hi in sel
                                 else "—")
                out.append(f"| {scene} | {g:g} | " + " | ".join(cells) + " |")
        out.append("")
    with open(args.out + ".tmp", "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(args.out + ".tmp", args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
