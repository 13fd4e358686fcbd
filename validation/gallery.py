#!/usr/bin/env python3
"""Image studies after the 2005 paper, each from one scene, with the ground truth.

--study fig12 (Fig. 12): renders scenes/fig12_reference.toml (a = 0.6,
g = 0.6, R_V = 5, an O5V star) and four variants, each changing one thing:
R_V = 3.1, a Sun-like (G2V) star of the same luminosity, albedo 0.8, g = 0.8.
Each variant is rendered twice with the same arguments: by the fast renderer
at its defaults (`nebula render`: single scattering and the scattering inside
each voxel from the tables, plus the light scattered between voxels from the
baked diffuse field) and by the path tracer (`nebula truth --equiangular
--spp S`, S = --truth-spp). The montage has the fast images on top, the truth
below each, and under each pair the V-band bias of the fast image against the
truth, Sigma(fast - truth)/Sigma truth over the pixels with signal, with its
standard error from the truth's noise, and the relative L2 error beyond that
noise (`nebula compare --json`).
--study pyramid (Fig. 9): the same scene with no multiple scattering between
voxels (`--set render.multiple_scattering=none`), with 1, 2 and 3 levels of the
2005 paper's resolution pyramid (`--levels N`), and with the diffuse field
(the default), beside one truth image, each captioned with its bias.
--study axial (Khalass 2021): scenes/axial_bipolar.toml, the thin bipolar
map lit by a star at its waist, seen along the axis, at 60 degrees and
across it, then the shells and the lopsided map at 60 degrees (no truth).
--study axial_deform (Khalass 2021 section 3.2): the lopsided (Calabash-like)
map, its render at 60 degrees without deformations and with colour and shape
deformations of each noise kind (simplex, fbm, turbulence, cellular), single
scattering (render.multiple_scattering = "none"); the map itself (tau_v,
written by `nebula bench axial --write-maps`) first.
--study axial_ms: validation/scenes/axial_lopsided_thick.toml (an axial map,
optical depths up to about 5 from the star on its axis) without light
scattered between texels and with the diffuse field (the default), beside
one truth image (the map voxelized in its own frame), captioned with biases.
Every image in a study, truth included, has the same exposure (the scene's
camera.exposure) and the same tone mapping as `nebula render -o X.png`
(value clamped to [0, 1], sRGB curve, 8 bits; red, green, blue from R, V, B),
so brightness and colour compare directly. Writes each image as HDF5 (the
data, which compare reads) and PNG into --renders, and the montage into --out.
--no-truth leaves the truth out (quick looks; the montage is the fast row).
--truth-strata K (default 4) samples each truth pixel's area in K x K strata:
the pixel's mean, which the fast renderer's pixels at a star stand for.
--render-only runs the renders and truths and stops (no numpy, h5py or
matplotlib needed: for a GPU machine without them); --reuse then makes the
montage elsewhere from those files, rendering only what is missing or was
rendered with other arguments (each HDF5 has its arguments beside it, in
NAME.h5.args).

Usage: /usr/bin/python3 validation/gallery.py [--study fig12|pyramid|axial|axial_deform|axial_ms]
           [--nebula build/bin/nebula] [--scene SCENE (default: the study's)]
           [--out docs/images] [--renders out/gallery] [--size 384]
           [--truth-spp 256 [--truth-strata 4] | --no-truth] [--backend auto] [--render-only | --reuse]
Needs numpy, h5py and matplotlib (Debian: python3-numpy, python3-h5py,
python3-matplotlib).
"""
import argparse
import json
import os
import subprocess
import sys

FIG12_SCENE = "scenes/fig12_reference.toml"
AXIAL_SCENE = "scenes/axial_bipolar.toml"
FAST_LABEL = "fast (default, diffuse field)"

# study: (montage file, title, scene, truth, [(key, panel title, extra render arguments)]).
# truth: "each" renders the truth of every variant with the variant's arguments (they may only change the
# scene, --set); "shared" renders one truth of the scene, which every variant (differing only in how the fast
# renderer works) is compared against; None: no truth.
STUDIES = {
    "fig12": ("fig12_study.png", "Parameter study after Magnor et al. 2005, Fig. 12 (same exposure throughout)",
              FIG12_SCENE, "each", [
        ("reference", "reference\na = 0.6, g = 0.6, R_V = 5, O5V", []),
        ("rv31", "R_V = 3.1", ["--set", "dust.R_V=3.1"]),
        ("sunlike", "Sun-like star (G2V)", ["--set", 'stars.0.class="G2V"']),
        ("albedo08", "albedo a = 0.8", ["--set", "dust.albedo=0.8"]),
        ("g08", "anisotropy g = 0.8", ["--set", "dust.g=0.8"]),
    ]),
    "pyramid": ("pyramid_levels.png",
                "Multiple scattering between voxels: none, 1 to 3 pyramid levels (Magnor et al. 2005, Fig. 9) "
                "and the diffuse field (default); same exposure",
                FIG12_SCENE, "shared", [
        ("levels0", "0 levels (no multiple\nscattering between voxels)", ["--set", "render.multiple_scattering=none"]),
    ] + [
        (f"levels{n}", f"pyramid, {n} level{'s' if n != 1 else ''}", ["--levels", str(n)]) for n in range(1, 4)
    ] + [
        ("diffuse", "diffuse field (default)", []),
    ]),
    "axial": ("axial_maps.png",
              "Axial nebulae from a 2D map (after Khalass 2021), a B0V star on the axis, same exposure",
              AXIAL_SCENE, None, [
        ("along", "bipolar, along the axis", ["--set", "camera.position=[0.0, 0.0, 6.0]",
                                              "--set", "camera.up=[0.0, 1.0, 0.0]"]),
        ("at60", "bipolar, 60 degrees", []),
        ("across", "bipolar, across the axis", ["--set", "camera.position=[6.0, 0.0, 0.0]"]),
        ("shells", "shells, 60 degrees", ["--set", 'axial.synthetic="shells"']),
        ("lopsided", "lopsided, 60 degrees", ["--set", 'axial.synthetic="lopsided"']),
    ]),
    "axial_deform": ("axial_deform.png",
                     "Asymmetry (after Khalass 2021, section 3.2): the lopsided map, plain and deformed (60 degrees)",
                     AXIAL_SCENE, None, [
        ("plain", "no deformation", []),
    ] + [
        (kind, f"{kind}: colour 0.8,\nshape pull up to 0.4",
         ["--set", f'axial.colour_deform.kind="{kind}"', "--set", "axial.colour_deform.amplitude=0.8",
          "--set", "axial.colour_deform.frequency=6",
          "--set", f'axial.shape_deform.kind="{kind}"', "--set", "axial.shape_deform.amplitude=0.4",
          "--set", "axial.shape_deform.frequency=8"])
        for kind in ("simplex", "fbm", "turbulence", "cellular")
    ]),
    "spectral": ("spectral_light_between_voxels.png",
                 "The spectral renderer (Barres 2023 projection, B, V, R filters) without and\n"
                 "with the light scattered between voxels, beside the truth; same exposure",
                 "scenes/fig12_spectral.toml", "shared", [
        ("none", "spectral, no light scattered\nbetween voxels", ["--set", "render.multiple_scattering=none"]),
        ("diffuse", "spectral (default,\ndiffuse field)", []),
    ]),
    "axial_ms": ("axial_diffuse.png",
                 "An axial map, a = g = 0.6, optical depths up to about 5 from the star:\n"
                 "light scattered between texels left out, and the diffuse field (default); same exposure",
                 "validation/scenes/axial_lopsided_thick.toml", "shared", [
        ("none", "no light scattered\nbetween texels", ["--set", "render.multiple_scattering=none"]),
        ("diffuse", "diffuse field (default)", []),
    ]),
}


def fail(message):
    print(f"gallery.py: error: {message}", file=sys.stderr)
    sys.exit(1)


def run(command, what):
    print("$", " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        fail(f"{what} failed: {result.stderr.strip() or result.stdout.strip()}")
    return result.stdout


def render_file(nebula, arguments, h5, what, reuse):
    """Runs `nebula arguments` (which write h5) and records the arguments in h5.args; with reuse, an h5 whose
    recorded arguments are the same is kept as it is (rendered before, perhaps on another machine)."""
    record = h5 + ".args"
    wanted = json.dumps([os.path.basename(a) if a == h5 else a for a in arguments])  # movable with its folder
    if reuse and os.path.isfile(h5) and os.path.isfile(record):
        with open(record) as f:
            if f.read() == wanted:
                print(f"  reusing {h5}", flush=True)
                return
    if os.path.exists(record):
        os.remove(record)  # until the new render is in place, no record may vouch for the file
    run([nebula] + arguments, what)
    with open(record + ".tmp", "w") as f:
        f.write(wanted)
    os.replace(record + ".tmp", record)


def write_png(h5_path, png_path):
    """The PNG of an HDF5 image exactly as `nebula render -o X.png` tone-maps it (docs/image_files.md):
    value x exposure clamped to [0, 1], sRGB curve (IEC 61966-2-1), rounded to 8 bits; red, green, blue from
    the bands R, V, B, grey from a single band; NaN shows as black."""
    import h5py
    import numpy as np
    import matplotlib.pyplot as plt

    with h5py.File(h5_path, "r") as f:
        image = f["image"][()].astype(np.float64)  # [band][y][x], row 0 at the top
        bands = f.attrs["bands"]  # an array of names (schema 2) or "B,V,R" (schema 1)
        if isinstance(bands, (bytes, str)):
            bands = (bands.decode() if isinstance(bands, bytes) else bands).split(",")
        else:
            bands = [b.decode() if isinstance(b, bytes) else str(b) for b in bands]
        # The pixels are radiance; the scene's camera.exposure is stored beside them (schema 2; schema 1
        # files had it in the pixels and store 1).
        exposure = float(f.attrs.get("exposure", 1.0))
    if len(bands) == 1:
        planes = [image[0]] * 3
    else:
        missing = [b for b in ("R", "V", "B") if b not in bands]
        if missing:
            fail(f"{h5_path}: bands {','.join(bands)}: a colour picture needs R, V and B")
        planes = [image[bands.index(b)] for b in ("R", "V", "B")]
    x = np.nan_to_num(np.stack(planes, axis=-1) * exposure, nan=0.0)
    x = np.clip(x, 0.0, 1.0)
    encoded = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    levels = np.floor(255.0 * encoded + 0.5).astype(np.uint8)  # lround: the values are not negative
    plt.imsave(png_path + ".tmp.png", levels)
    os.replace(png_path + ".tmp.png", png_path)


def caption(bands):
    """The V-band bias of a fast image against the truth (the first band if there is no V)."""
    band = next((b for b in bands if b["band"] == "V"), bands[0])

    def signed(v):
        return f"{100 * v:+.1f}%".replace("-", "\u2212")

    error = 100 * band["bias_stderr"]
    text = f"{band['band']} bias {signed(band['bias'])} \u00b1 {error:.{2 if error < 0.1 else 1}f}%"
    if band.get("has_variance"):
        text += f"\n(L2 beyond noise {band['rel_l2_excess']:.2f})"
    return text


def panel(ax, path):
    """An image without ticks or frame, keeping the axis labels (row labels and captions)."""
    import matplotlib.pyplot as plt

    ax.imshow(plt.imread(path))
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(False)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", default="fig12", choices=sorted(STUDIES))
    parser.add_argument("--nebula", default="build/bin/nebula")
    parser.add_argument("--scene", help="the scene (default: the study's own)")
    parser.add_argument("--out", default="docs/images", help="folder for the montage")
    parser.add_argument("--renders", default="out/gallery", help="folder for the single images (HDF5 and PNG)")
    parser.add_argument("--size", type=int, default=384, help="image width and height in pixels")
    parser.add_argument("--truth-spp", type=int, default=256,
                        help="samples per pixel of the truth (nebula truth --equiangular --spp)")
    parser.add_argument("--truth-strata", type=int, default=4,
                        help="the truth's pixel-area strata per side, the largest up to this whose square divides "
                             "--truth-spp (the pixel's mean, as the fast renderer's star pixels take it; 1: the "
                             "pixel's centre ray)")
    parser.add_argument("--no-truth", action="store_true", help="the fast images only (quick looks)")
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--render-only", action="store_true",
                        help="render the HDF5 files into --renders and stop (no numpy, h5py or matplotlib needed)")
    parser.add_argument("--reuse", action="store_true",
                        help="keep the HDF5 files in --renders rendered with the same arguments (from --render-only)")
    args = parser.parse_args()
    if args.render_only and args.reuse:
        fail("--render-only and --reuse: give one (render here, or compose from earlier renders)")
    if args.render_only and args.study == "axial_deform":
        fail("--render-only: the axial_deform study reads its map with h5py while rendering; run it whole")
    montage_name, suptitle, scene, truth_mode, variants = STUDIES[args.study]
    args.scene = args.scene or scene
    if args.no_truth:
        truth_mode = None
    if not os.access(args.nebula, os.X_OK):
        fail(f"{args.nebula}: not an executable (build first: scripts/test.sh)")
    if not os.path.isfile(args.scene):
        fail(f"{args.scene}: no such scene file")
    if not os.path.isdir(args.out):
        fail(f"{args.out}: no such folder")
    os.makedirs(args.renders, exist_ok=True)
    if args.size < 16:
        fail("--size: at least 16 pixels")
    if truth_mode and args.truth_spp < 2:
        fail("--truth-spp: at least 2 (the truth's variance needs two samples)")
    if args.truth_strata < 1:
        fail("--truth-strata: at least 1")
    # The pixel's mean from k x k jittered strata (any k estimates the same mean), as accuracy_report.py takes it.
    strata_side = max(j for j in range(1, args.truth_strata + 1) if args.truth_spp % (j * j) == 0)
    strata = ["--set", f"render.samples_per_pixel={strata_side * strata_side}"] if strata_side > 1 else []

    if not args.render_only:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

    size = ["--width", str(args.size), "--height", str(args.size)]
    truth_label = (f"truth (path tracer, {args.truth_spp} spp"
                   + (f", {strata_side}x{strata_side} strata)" if strata_side > 1 else ")"))

    def render_truth(name, extra):
        h5 = os.path.join(args.renders, f"{args.study}_{name}.h5")
        render_file(args.nebula, ["truth", args.scene, "-o", h5, "--force", "-q", "--equiangular", "--spp",
                                  str(args.truth_spp), "--backend", args.backend] + size + strata + extra,
                    h5, f"the truth of {name}", args.reuse)
        png = os.path.splitext(h5)[0] + ".png"
        if not args.render_only:
            write_png(h5, png)
        return h5, png

    shared_truth = render_truth("truth", []) if truth_mode == "shared" else None
    map_png = None
    if args.study == "axial_deform":
        # A square 512^2 lopsided map 4 pc long centred on the star, seen from 12 pc; the map panel is
        # the same synthetic map as the benchmark writes it (its tau_v; the scene scales it by tau_scale).
        common = ["--set", 'axial.synthetic="lopsided"', "--set", "axial.nx=512", "--set", "axial.nr=512",
                  "--set", "axial.length_pc=4.0", "--set", "axial.origin=[0.0, 0.0, -2.0]",
                  "--set", "axial.emission_scale=0.05",
                  "--set", "camera.position=[10.392, 0.0, 6.0]", "--set", "camera.fov_deg=22",
                  "--set", 'render.multiple_scattering="none"']  # single scattering: the shapes show, quickly
        variants = [(k, t, common + extra) for k, t, extra in variants]
        run([args.nebula, "bench", "axial", "--backend", "cpu", "--maps", "lopsided", "--map-size", "512",
             "--image", "8", "--inclinations", "0", "--modes", "naive", "--repeats", "1", "--deform", "off",
             "--emission-only", "--write-maps", args.renders], "writing the map")
        import h5py
        import numpy as np
        with h5py.File(os.path.join(args.renders, "lopsided.h5"), "r") as f:
            tau = f["image"][()][0].astype(np.float64)  # band tau_v, [row][column], the axis at the bottom
        map_png = os.path.join(args.renders, "axial_deform_map.png")
        shown = np.sqrt(tau / max(tau.max(), 1e-30))
        plt.imsave(map_png + ".tmp.png", shown, cmap="magma", vmin=0.0, vmax=1.0)
        os.replace(map_png + ".tmp.png", map_png)
    # (title, fast PNG, truth PNG or None, caption or None) per variant
    panels = []
    for key, title, extra in variants:
        h5 = os.path.join(args.renders, f"{args.study}_{key}.h5")
        render_file(args.nebula, ["render", args.scene, "-o", h5, "--force", "-q", "--backend", args.backend] +
                    size + extra, h5, f"rendering {key}", args.reuse)
        png = os.path.splitext(h5)[0] + ".png"
        truth = render_truth(f"{key}_truth", extra) if truth_mode == "each" else shared_truth
        if args.render_only:
            continue
        write_png(h5, png)
        text = None
        if truth:
            text = caption(json.loads(run([args.nebula, "compare", h5, truth[0], "--json"],
                                          f"comparing {key} with the truth"))["bands"])
            print(f"  {key}: {text.replace(chr(10), ' ')}", flush=True)
        panels.append((title, png, truth[1] if truth_mode == "each" else None, text))
    if args.render_only:
        print(f"rendered into {args.renders}; compose with --reuse")
        return
    if map_png:
        panels.insert(0, ("the map: sqrt(tau_v / max)\nx along the axis, r up", map_png, None, None))

    w = 3.2  # inches per panel
    if truth_mode == "each":
        # Two rows: the fast image on top, the truth below, the bias under each pair.
        fig, axes = plt.subplots(2, len(panels), figsize=(w * len(panels) + 0.4, 2 * w + 1.6), dpi=100,
                                 squeeze=False)
        for j, (title, fast_png, truth_png, text) in enumerate(panels):
            panel(axes[0, j], fast_png)
            axes[0, j].set_title(title, fontsize=10)
            panel(axes[1, j], truth_png)
            axes[1, j].set_xlabel(text, fontsize=10)
        axes[0, 0].set_ylabel(FAST_LABEL, fontsize=10)
        axes[1, 0].set_ylabel(truth_label, fontsize=10)
    else:
        # One row; with a shared truth, the truth last and the bias under each fast image.
        n = len(panels) + (1 if shared_truth else 0)
        fig, axes = plt.subplots(1, n, figsize=(w * n, w + (1.2 if shared_truth else 0.5)), dpi=100, squeeze=False)
        axes = axes[0]
        for ax, (title, png, _, text) in zip(axes, panels):
            panel(ax, png)
            ax.set_title(title, fontsize=10)
            if text:
                ax.set_xlabel(text, fontsize=10)
        if shared_truth:
            panel(axes[-1], shared_truth[1])
            axes[-1].set_title(truth_label.replace(" (", "\n("), fontsize=10)
            axes[-1].set_xlabel("the reference of the\nbiases on the left", fontsize=10)
        elif args.study == "fig12":
            axes[0].set_ylabel(FAST_LABEL, fontsize=10)
    fig.suptitle(suptitle)
    fig.tight_layout(rect=(0, 0, 1, 0.9) if args.study == "axial_deform" else None)
    montage = os.path.join(args.out, montage_name)
    fig.savefig(montage + ".tmp.png")
    os.replace(montage + ".tmp.png", montage)
    print(f"wrote {montage}")


if __name__ == "__main__":
    main()
