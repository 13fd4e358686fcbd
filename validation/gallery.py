#!/usr/bin/env python3
"""Image studies after the 2005 paper, each from one scene.

--study fig12 (Fig. 12): renders scenes/fig12_reference.toml (a = 0.6,
g = 0.6, R_V = 5, an O5V star) and four variants, each changing one thing:
R_V = 3.1, a Sun-like (G2V) star of the same luminosity, albedo 0.8, g = 0.8.
--study pyramid (Fig. 9): the same scene with 0, 1, 2 and 3 pyramid levels.
--study axial (Khalass 2021): scenes/axial_bipolar.toml, the thin bipolar
map lit by a star at its waist, seen along the axis, at 60 degrees and
across it, then the shells and the lopsided map at 60 degrees.
Every image in a study has the same exposure, so brightness and colour compare
directly. Writes one PNG per variant (into --renders) and a montage (into
--out).

Usage: /usr/bin/python3 validation/gallery.py [--study fig12|pyramid|axial]
           [--nebula build/bin/nebula] [--scene SCENE (default: the study's)]
           [--out docs/images] [--size 384] [--backend auto]
Needs numpy and matplotlib (Debian: python3-numpy, python3-matplotlib).
"""
import argparse
import os
import subprocess
import sys

FIG12_SCENE = "scenes/fig12_reference.toml"
AXIAL_SCENE = "scenes/axial_bipolar.toml"

# study: (montage file, title, scene, [(key, panel title, extra render arguments)])
STUDIES = {
    "fig12": ("fig12_study.png", "Parameter study after Magnor et al. 2005, Fig. 12 (same exposure throughout)",
              FIG12_SCENE, [
        ("reference", "reference\na = 0.6, g = 0.6, R_V = 5, O5V", []),
        ("rv31", "R_V = 3.1", ["--set", "dust.R_V=3.1"]),
        ("sunlike", "Sun-like star (G2V)", ["--set", 'stars.0.class="G2V"']),
        ("albedo08", "albedo a = 0.8", ["--set", "dust.albedo=0.8"]),
        ("g08", "anisotropy g = 0.8", ["--set", "dust.g=0.8"]),
    ]),
    "pyramid": ("pyramid_levels.png",
                "Wide-range multiple scattering: 0 to 3 pyramid levels, after Magnor et al. 2005, Fig. 9",
                FIG12_SCENE, [
        (f"levels{n}", f"{n} level{'s' if n != 1 else ''}" + (" (plain render)" if n == 0 else ""),
         ["--levels", str(n)]) for n in range(4)
    ]),
    "axial": ("axial_maps.png",
              "Axial nebulae from a 2D map (after Khalass 2021), a B0V star on the axis, same exposure",
              AXIAL_SCENE, [
        ("along", "bipolar, along the axis", ["--set", "camera.position=[0.0, 0.0, 6.0]",
                                              "--set", "camera.up=[0.0, 1.0, 0.0]"]),
        ("at60", "bipolar, 60 degrees", []),
        ("across", "bipolar, across the axis", ["--set", "camera.position=[6.0, 0.0, 0.0]"]),
        ("shells", "shells, 60 degrees", ["--set", 'axial.synthetic="shells"']),
        ("lopsided", "lopsided, 60 degrees", ["--set", 'axial.synthetic="lopsided"']),
    ]),
}


def fail(message):
    print(f"gallery.py: error: {message}", file=sys.stderr)
    sys.exit(1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", default="fig12", choices=sorted(STUDIES))
    parser.add_argument("--nebula", default="build/bin/nebula")
    parser.add_argument("--scene", help="the scene (default: the study's own)")
    parser.add_argument("--out", default="docs/images", help="folder for the montage")
    parser.add_argument("--renders", default="out/gallery", help="folder for the single images")
    parser.add_argument("--size", type=int, default=384, help="image width and height in pixels")
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()
    montage_name, suptitle, scene, variants = STUDIES[args.study]
    args.scene = args.scene or scene
    if not os.access(args.nebula, os.X_OK):
        fail(f"{args.nebula}: not an executable (build first: scripts/test.sh)")
    if not os.path.isfile(args.scene):
        fail(f"{args.scene}: no such scene file")
    if not os.path.isdir(args.out):
        fail(f"{args.out}: no such folder")
    os.makedirs(args.renders, exist_ok=True)
    if args.size < 16:
        fail("--size: at least 16 pixels")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = []
    for key, title, extra in variants:
        path = os.path.join(args.renders, f"{args.study}_{key}.png")
        command = [args.nebula, "render", args.scene, "-o", path, "--force", "-q",
                   "--backend", args.backend, "--width", str(args.size), "--height", str(args.size)] + extra
        print("$", " ".join(command), flush=True)
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            fail(f"rendering {key} failed: {result.stderr.strip()}")
        panels.append((title, path))

    fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.7), dpi=100)
    for ax, (title, path) in zip(axes, panels):
        ax.imshow(plt.imread(path))
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    fig.suptitle(suptitle)
    fig.tight_layout()
    montage = os.path.join(args.out, montage_name)
    fig.savefig(montage + ".tmp.png")
    os.replace(montage + ".tmp.png", montage)
    print(f"wrote {montage}")


if __name__ == "__main__":
    main()
