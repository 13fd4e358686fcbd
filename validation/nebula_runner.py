"""Runs the nebula command line for the validation studies: one work folder, its own table cache;
the studies' shared options, work folder and albedo x g grid of truths."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Runner:
    def __init__(self, args):
        self.nebula = os.path.abspath(args.nebula)
        self.work = os.path.abspath(args.work)
        self.backend = args.backend
        self.env = dict(os.environ, NEBULA_CACHE_DIR=os.path.join(self.work, "cache"))

    def run(self, argv):
        r = subprocess.run([self.nebula] + argv, capture_output=True, text=True, env=self.env, cwd=self.work)
        if r.returncode != 0:
            raise SystemExit(f"nebula {' '.join(argv)} failed ({r.returncode}): {r.stderr.strip()}")
        return r.stdout

    def compare(self, a, b):
        """Per band: bias, its standard error, L2 beyond the truth's noise, ... (`nebula compare --json`)."""
        return json.loads(self.run(["compare", a, b, "--json"]))["bands"]


def study_arguments(description, work, out, scenes):
    """The options every truth study takes; the study adds its own before parsing."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--nebula", default=os.path.join(ROOT, "build", "bin", "nebula"))
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--work", default=work)
    ap.add_argument("--spp", type=int, default=512, help="truth samples per pixel")
    ap.add_argument("--truth-strata", type=int, default=1,
                    help="the truth's pixel-area strata per side (render.samples_per_pixel = this squared, for the "
                         "truth only; 1: each pixel's centre ray). The fast renderer's one ray per pixel stands for "
                         "the pixel's area near a star, so the pixels around one compare only with strata; spp must "
                         "be a multiple of its square")
    ap.add_argument("--fig12-pixels", type=int, default=128, help="image size of the Fig. 12 scene")
    ap.add_argument("--albedos", default="0.3,0.6,0.9")
    ap.add_argument("--gs", default="0,0.6,0.9")
    ap.add_argument("--scenes", default=",".join(scenes))
    ap.add_argument("--out", default=out)
    ap.add_argument("--machine", default="", help="the machine, for the page")
    return ap


def prepare_work(args):
    """The work folder with validation/scenes in it, and the layer and wedge grids where asked for (kept when
    already there, so a machine without h5py can run the study in a folder prepared elsewhere)."""
    os.makedirs(args.work, exist_ok=True)
    for f in os.listdir(os.path.join(ROOT, "validation", "scenes")):
        shutil.copy(os.path.join(ROOT, "validation", "scenes", f), args.work)
    made = all(os.path.exists(os.path.join(args.work, f)) for f in ("layers.h5", "wedge.h5"))
    if not made and any(s.startswith(("layer", "wedge")) for s in args.scenes.split(",")):
        sys.path.insert(0, os.path.join(ROOT, "validation"))
        from accuracy_report import write_densities  # numpy, h5py
        write_densities(args.work)


def truth_grid(runner, args, scene, truth_scene):
    """For every albedo and g of the study: renders the truth of truth_scene and yields (a, g,
    the render options both share (image size, dust), a tag for file names, the truth's file,
    its seconds)."""
    size = ["--width", str(args.fig12_pixels), "--height", str(args.fig12_pixels)] if scene == "fig12_reference" \
        else []
    for a in (float(x) for x in args.albedos.split(",")):
        for g in (float(x) for x in args.gs.split(",")):
            shared = size + ["--set", f"dust.albedo={a}", "--set", f"dust.g={g}"]
            tag = f"{scene}_a{a}_g{g}"
            truth = os.path.join(args.work, f"truth_{tag}.h5")
            t0 = time.time()
            strata = ["--set", f"render.samples_per_pixel={args.truth_strata ** 2}"] if args.truth_strata > 1 else []
            runner.run(["truth", truth_scene, "--spp", str(args.spp), "--equiangular", "--backend", runner.backend,
                        "-q", "--force", "-o", truth] + shared + strata)
            yield a, g, shared, tag, truth, time.time() - t0


def write_rows(rows, out):
    """The rows as JSON beside the page `out`, written aside and renamed."""
    path = os.path.splitext(out)[0] + ".json"
    with open(path + ".tmp", "w") as f:
        json.dump(rows, f, indent=1)
    os.replace(path + ".tmp", path)


def read_rows(paths, methods):
    """The rows of a study's JSON files (--merge) whose method is one of `methods`; one line naming the file
    for a file that cannot be read or holds no study's rows."""
    rows = []
    for path in paths:
        try:
            with open(path) as f:
                part = json.load(f)
        except (OSError, ValueError) as e:
            raise SystemExit(f"--merge: {path}: cannot read the study's JSON rows ({e})")
        if not isinstance(part, list) or not all(isinstance(r, dict) and "scene" in r and "method" in r for r in part):
            raise SystemExit(f"--merge: {path}: not a study's JSON rows (a list of rows with scene and method)")
        rows += [r for r in part if r["method"] in methods]
    return rows
