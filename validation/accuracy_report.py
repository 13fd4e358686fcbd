#!/usr/bin/env python3
"""Speed against error of the fast renderer and of the path tracer (issue 5).

One command regenerates everything (results, plots, docs/accuracy.md):

    /usr/bin/python3 validation/accuracy_report.py --nebula build/bin/nebula

(add --backend cuda on a GPU; any python3 with numpy, matplotlib and h5py). For each scene of the standard
set (validation/scenes/*.toml) it renders a reference with `nebula truth`,
then runs `nebula render` as each knob varies and `nebula truth` at growing
spp, compares each image to the reference with `nebula compare --json`, and
writes docs/accuracy.md and docs/images/accuracy_*.png. The fast renderer's
rows, by how they add the light scattered between voxels:
  fast, fast smooth, fast table: the default, the diffuse field (its default
    photons), as the table's photons per row, the smooth mode's step and the
    table's tau and mu resolution vary;
  fast diffuse: the diffuse field's photons per band (--diffuse-photons,
    `--set render.diffuse_photons=N`) at the default tables;
  fast none: none (`--set render.multiple_scattering=none`): single
    scattering and the scattering inside each voxel only;
  fast pyramid: the 2005 paper's resolution pyramid, 1 to 4 levels
    (`--levels N`; measured when `nebula render` has `--levels`).
Times are what the commands report: the fast renderer's star bake, diffuse-
field bake or pyramid levels, and march (tables are generated once and
cached; their cost is listed apart), the path tracer's tracing time.

The findings (the prose that says what the tables mean) live only in
docs/accuracy.md, between marker comments; a rerun reads them from the
existing page and writes them back in the same places (read_findings,
findings_block). Edit them there.
"""
import argparse
import json
import os
import platform
import re
import subprocess
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["thin_nebula", "thick_nebula", "layer_front", "layer_behind", "wedge"]


def write_densities(folder):
    """The layer and wedge grids of validation/scenes (32^3 over 2 pc, deterministic)."""
    n, voxel = 32, 2.0 / 32
    rng = np.random.default_rng(5)
    path = os.path.join(folder, "layers.h5")
    if not os.path.exists(path):
        with h5py.File(path + ".tmp", "w") as f:
            for y0 in (12, 20):
                g = np.zeros((n, n, n), np.float32)  # [z][y][x]
                g[:, y0:y0 + 4, :] = 0.25 * (1 + 0.3 * rng.uniform(-1, 1, (n, 4, n)))
                d = f.create_dataset(f"layer_y{y0}", data=g)
                d.attrs["voxel_size"] = voxel
        os.replace(path + ".tmp", path)
    path = os.path.join(folder, "wedge.h5")
    if not os.path.exists(path):
        z, y, x = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
        g = np.full((n, n, n), 0.02, np.float32)
        g[x >= 14 + 0.6 * np.abs(y - 15.5)] = 1.5  # sharp slanted faces, apex towards the star
        with h5py.File(path + ".tmp", "w") as f:
            d = f.create_dataset("tau_v", data=g)
            d.attrs["voxel_size"] = voxel
        os.replace(path + ".tmp", path)


class Runner:
    def __init__(self, args):
        self.nebula = os.path.abspath(args.nebula)
        self.work = os.path.abspath(args.work)
        self.backend = args.backend
        self.transmittance = args.transmittance
        self.equiangular = args.equiangular
        self.truth_strata = args.truth_strata
        os.makedirs(self.work, exist_ok=True)
        self.env = dict(os.environ, NEBULA_CACHE_DIR=os.path.join(self.work, "cache"))
        help_text = self.run(["render", "--help"])
        self.has_levels = "--levels" in help_text

    def run(self, argv):
        r = subprocess.run([self.nebula] + argv, capture_output=True, text=True, env=self.env, cwd=self.work)
        if r.returncode != 0:
            raise SystemExit(f"nebula {' '.join(argv)} failed ({r.returncode}): {r.stderr.strip()}")
        return r.stdout

    def truth(self, scene, spp, seed, out, extra=()):
        # The pixel's mean (what the fast renderer's pixels stand for near a star), from k x k jittered strata:
        # the largest k up to --truth-strata whose square divides spp (any k estimates the same mean).
        k = max(j for j in range(1, self.truth_strata + 1) if spp % (j * j) == 0)
        strata = ["--set", f"render.samples_per_pixel={k * k}"] if k > 1 else []
        text = self.run(["truth", scene, "--spp", str(spp), "--seed", str(seed), "--backend", self.backend, "-q",
                         "--transmittance", self.transmittance, "--force", "-o", out] +
                        (["--equiangular"] if self.equiangular else []) + strata + list(extra))
        return float(re.search(r"tracing ([0-9.eE+-]+) s", text).group(1))

    def render(self, scene, out, extra):
        """Runs the fast renderer; returns (seconds, how it added multiple scattering between voxels). The time
        is the star bake, the diffuse field's bake or the pyramid's coarser levels (build, bake; their render
        is in the marching time), and the march."""
        text = self.run(["render", scene, "--backend", self.backend, "-q", "--force", "-o", out] + extra)
        number = r"([0-9.eE+-]+)"
        bake = re.search(r"\n\s*bake: .*?, " + number + " s", text)
        march = float(re.search(r"render: " + number + " s marching", text).group(1))
        diffuse = re.search(r"diffuse field \(light scattered between voxels\):.*?; " + number + r" s \(photon passes",
                            text)
        levels = re.findall(r"pyramid level \d+: .*?build " + number + " s, bake " + number + " s", text)
        seconds = march + (float(bake.group(1)) if bake else 0.0) + (float(diffuse.group(1)) if diffuse else 0.0)
        seconds += sum(float(b) + float(k) for b, k in levels)
        with h5py.File(out, "r") as f:
            how = f.attrs.get("multiple_scattering", b"")
        return seconds, how.decode() if isinstance(how, bytes) else str(how)

    def compare(self, a, b):
        c = json.loads(self.run(["compare", a, b, "--json"]))
        return c["bands"]

    def tabulate(self, out, photons, tau_bins, mu_bins):
        """Makes the table once; its generation time is kept beside it (out.seconds)."""
        if os.path.exists(out) and os.path.exists(out + ".seconds"):
            with open(out + ".seconds") as f:
                return float(f.read())
        t0 = time.time()
        self.run(["tabulate", "--photons", str(photons), "--tau-bins", str(tau_bins), "--mu-bins", str(mu_bins),
                  "--binning", "uniform-theta", "--backend", self.backend, "-q", "--force", "-o", out])
        seconds = time.time() - t0
        with open(out + ".seconds", "w") as f:
            f.write(f"{seconds:.3f}\n")
        return seconds


def summarise(bands):
    """Mean over bands of the metrics the report uses."""
    keys = ["rel_l1", "rel_l2", "worst_1pct", "bias", "noise_rel_l2", "rel_l2_excess"]
    out = {k: float(np.mean([b[k] for b in bands])) for k in keys}
    # Bands are traced on independent random streams: the mean's error adds in quadrature.
    out["bias_stderr"] = float(np.sqrt(np.sum([b["bias_stderr"] ** 2 for b in bands])) / len(bands))
    return out


def study(r, name, args, rows, notes):
    scene = os.path.join(ROOT, "validation", "scenes", name + ".toml")
    d = os.path.join(r.work, name)
    os.makedirs(d, exist_ok=True)
    ref = os.path.join(d, "truth_ref.h5")
    t_ref = r.truth(scene, args.ref_spp, 1, ref)
    rows.append(dict(scene=name, method="truth (reference)", knob="spp", value=args.ref_spp, seconds=t_ref,
                     **summarise(r.compare(ref, ref))))
    # Scattering orders: single scattering only (and up to 2), against the full truth: how much of the image
    # is light scattered more than once.
    for orders in (1, 2):
        out = os.path.join(d, f"truth_orders_{orders}.h5")
        t = r.truth(scene, args.orders_spp, 50 + orders, out, ["--max-orders", str(orders)])
        rows.append(dict(scene=name, method="truth orders", knob="max orders", value=orders, seconds=t,
                         **summarise(r.compare(out, ref))))
    for k, spp in enumerate(args.truth_spp):
        out = os.path.join(d, f"truth_{spp}.h5")
        t = r.truth(scene, spp, 100 + k, out)
        rows.append(dict(scene=name, method="truth", knob="spp", value=spp, seconds=t, **summarise(r.compare(out, ref))))

    def fast(method, knob, value, tag, extra):
        """One fast render (fast_<tag>.h5) against the reference; the row records how it added the light
        scattered between voxels, as the image's metadata says."""
        out = os.path.join(d, f"fast_{tag}.h5")
        t, how = r.render(scene, out, extra)
        rows.append(dict(scene=name, method=method, knob=knob, value=value, seconds=t, multiple_scattering=how,
                         **summarise(r.compare(out, ref))))

    defaults = ["--table-photons", str(args.default_photons)]
    # The default multiple scattering between voxels (the diffuse field) in all of: fast, fast smooth, fast table.
    for photons in args.photons:
        fast("fast", "table photons/row", photons, f"photons_{photons}", ["--table-photons", str(photons)])
    for step in args.steps:
        fast("fast smooth", "step (voxels)", step, f"smooth_{step}", defaults + ["--smooth", str(step)])
    for tau_bins, mu_bins in args.resolutions:
        table = os.path.join(r.work, f"table_{tau_bins}x{mu_bins}.h5")
        sets = []
        for band in ("B", "V", "R"):
            sets += ["--set", f"dust.tables.{band}={table}"]
        fast("fast table", "tau x mu bins", f"{tau_bins}x{mu_bins}", f"table_{tau_bins}x{mu_bins}", sets)
    # How the light scattered between voxels is added: the diffuse field's photons, none, the 2005 pyramid.
    for photons in args.diffuse_photons:
        fast("fast diffuse", "diffuse photons/band", photons, f"diffuse_{photons}",
             defaults + ["--set", f"render.diffuse_photons={photons}"])
    fast("fast none", "multiple scattering", "none", "none", defaults + ["--set", "render.multiple_scattering=none"])
    if r.has_levels:
        for levels in args.levels:
            fast("fast pyramid", "levels", levels, f"levels_{levels}", defaults + ["--levels", str(levels)])


# The fast renderer's rows by method: what each varies and how it adds the light scattered between voxels.
# "fast", "fast smooth" and "fast table" run at the renderer's default, the diffuse field (method_label says so
# when the rows' images say so; results from before the diffuse field was the default are not relabelled).
METHODS = {
    "truth": "truth (path tracer): spp",
    "fast": "fast: table photons/row",
    "fast smooth": "fast smooth: step",
    "fast table": "fast: table τ × μ bins",
    "fast diffuse": "fast, diffuse field: photons/band",
    "fast none": "fast, none between voxels",
    "fast pyramid": "fast, pyramid (2005): levels",
}
DEFAULT_SUFFIX = " (diffuse field, default)"


def uses_diffuse(rows, method):
    """Whether every row of this method added the light scattered between voxels by the diffuse field."""
    sel = [x for x in rows if x["method"] == method]
    return bool(sel) and all(str(x.get("multiple_scattering", "")).startswith("diffuse") for x in sel)


def method_label(rows, method):
    label = METHODS.get(method, method)
    if method in ("fast", "fast smooth", "fast table") and uses_diffuse(rows, method):
        label += DEFAULT_SUFFIX
    return label


def table_label(rows, method):
    """The method column of the per-scene tables: the method, and the diffuse field where it is the default."""
    if method in ("fast", "fast smooth", "fast table") and uses_diffuse(rows, method):
        return method + DEFAULT_SUFFIX
    return method


def backend_name(backend):
    return {"cpu": "CPU", "cuda": "GPU, CUDA"}.get(backend, f"backend {backend}")


def short_count(n):
    """16384 -> 16k, 1048576 -> 1M (photon counts on the plot)."""
    n = int(n)
    if n >= 1 << 20 and n % (1 << 20) == 0:
        return f"{n >> 20}M"
    if n >= 1 << 10 and n % (1 << 10) == 0:
        return f"{n >> 10}k"
    return f"{n:g}"


def plot(rows, images, backend):
    # Imported here: the study scripts that borrow this module's grids need no plotting.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(images, exist_ok=True)
    # method: (matplotlib format, colour, marker size, point labels). Sweeps over one knob are joined by a line.
    styles = {
        "truth": ("o-", "tab:blue", 5, None),
        "fast": ("s", "tab:orange", 5, None),
        "fast smooth": ("^", "tab:olive", 5, None),
        "fast table": ("D", "tab:brown", 4, None),
        "fast diffuse": ("P-", "tab:green", 7, lambda v: short_count(v)),
        "fast none": ("X", "tab:red", 8, None),
        "fast pyramid": ("v-", "tab:purple", 6, lambda v: str(v)),
    }
    # (truth orders rows are a diagnostic of the scene, not a method: left out of this plot)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    # One legend below the panels, as many columns as fit (about 3.5 inches each), the figure taller by its rows.
    present = [m for m in styles if any(r["method"] == m for r in rows)]
    ncol = max(1, min(4, len(present), int(4 * len(scenes) / 3.5)))
    legend_inches = 0.2 * -(-len(present) // ncol) + 0.15
    fig, axes = plt.subplots(1, len(scenes), figsize=(4 * len(scenes), 3.8 + legend_inches), sharey=True,
                             squeeze=False)
    axes = axes[0]
    handles = {}
    for ax, scene in zip(axes, scenes):
        for method, (style, colour, size, point_label) in styles.items():
            sel = [r for r in rows if r["scene"] == scene and r["method"] == method]
            if not sel:
                continue
            if style.endswith("-"):
                sel = sorted(sel, key=lambda r: r["value"])
            # The error beyond the reference's noise; the truth's own error is its noise.
            err = [max(r["rel_l2_excess"], 1e-4) if method != "truth" else r["rel_l2"] for r in sel]
            t = [r["seconds"] for r in sel]
            (line,) = ax.loglog(t, err, style, color=colour, ms=size, lw=1, alpha=0.85)
            handles.setdefault(method, line)
            if point_label:
                for x, y, r in zip(t, err, sel):
                    ax.annotate(point_label(r["value"]), (x, y), textcoords="offset points", xytext=(4, 3),
                                fontsize=6, color=colour)
        ref = [r for r in rows if r["scene"] == scene and r["method"] == "truth (reference)"][0]
        ax.axhline(ref["noise_rel_l2"] / np.sqrt(2), color="grey", lw=0.8, ls=":")
        ax.set_title(scene)
        ax.set_xlabel(f"time (s, {backend_name(backend)})")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("relative L2 error against the truth")
    fig.legend(list(handles.values()), [method_label(rows, m) for m in handles], loc="lower center",
               ncol=ncol, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, legend_inches / fig.get_figheight(), 1, 1))
    fig.savefig(os.path.join(images, "accuracy_time_vs_error.png"), dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(5, 3.8))
    for scene in scenes:
        sel = [r for r in rows if r["scene"] == scene and r["method"] == "truth"]
        ax.loglog([r["value"] for r in sel], [r["rel_l2"] for r in sel], "o-", label=scene)
    spp = np.array([min(r["value"] for r in rows if r["method"] == "truth"),
                    max(r["value"] for r in rows if r["method"] == "truth")], float)
    ax.loglog(spp, 0.5 * (spp / spp[0]) ** -0.5, "k--", lw=0.8, label="spp^-1/2")
    ax.set_xlabel("samples per pixel")
    ax.set_ylabel("relative L2 error against the reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(images, "accuracy_truth_convergence.png"), dpi=110)
    plt.close(fig)


def fmt(v):
    return f"{v:.3g}" if isinstance(v, float) else str(v)


# The findings (what the numbers mean) are written by hand in docs/accuracy.md itself, between these
# markers. A rerun reads them from the existing page and writes them back in the same places.
FINDINGS_BLOCKS = {
    "findings": ("<!-- findings: edit here; validation/accuracy_report.py keeps this block -->",
                 "<!-- end of findings -->"),
    "diffuse findings": ("<!-- diffuse findings: edit here; validation/accuracy_report.py keeps this block -->",
                         "<!-- end of diffuse findings -->"),
    "pyramid findings": ("<!-- pyramid findings: edit here; validation/accuracy_report.py keeps this block -->",
                         "<!-- end of pyramid findings -->"),
}
FINDINGS_PLACEHOLDER = "*Findings go here: what the table above shows, written by hand (a rerun keeps this block).*"


def read_findings(path):
    """The hand-written findings blocks of an existing page: name -> text between the markers (None if absent)."""
    found = dict.fromkeys(FINDINGS_BLOCKS)
    if not os.path.exists(path):
        return found
    with open(path, encoding="utf-8") as f:
        page = f.read()
    for name, (begin, end) in FINDINGS_BLOCKS.items():
        i = page.find(begin)
        if i < 0:
            continue
        j = page.find(end, i + len(begin))
        if j < 0:
            # Never drop hand-written text: stop before the page is overwritten.
            raise SystemExit(f"{path}: the {name} block has its start marker but no end marker ({end}); fix the "
                             "page, then rerun with --from-json <work>/results.json")
        found[name] = page[i + len(begin):j].strip()
    return found


def findings_block(name, findings):
    """The block as it goes into the page: start marker, the kept text (or the placeholder), end marker."""
    begin, end = FINDINGS_BLOCKS[name]
    return f"{begin}\n\n{findings.get(name) or FINDINGS_PLACEHOLDER}\n\n{end}\n"


def level_range(rows):
    """The pyramid rows' levels in words: "1 to 4 levels", "2 levels", "1 level"."""
    levels = sorted({x["value"] for x in rows if x["method"] == "fast pyramid"})
    if not levels:
        return "no levels measured"
    if len(levels) == 1:
        return f"{levels[0]} level{'s' if levels[0] != 1 else ''}"
    return f"{levels[0]} to {levels[-1]} levels"


def cell(x, third="worst"):
    """A row as one table cell: bias, the L2 error beyond the truth's noise, then the worst 1% or the time."""
    if x is None:
        return "—"
    last = f"{x['worst_1pct']:.2f}" if third == "worst" else f"{x['seconds']:.3g} s"
    return f"{100 * x['bias']:+.1f}%, {x['rel_l2_excess']:.3f}, {last}"


def write_markdown(rows, args, r, table_times, path, elapsed):
    machine = args.machine or f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"
    findings = read_findings(path)
    scenes = list(dict.fromkeys(x["scene"] for x in rows))

    def one(scene, method, value):
        sel = [x for x in rows if x["scene"] == scene and x["method"] == method and x["value"] == value]
        return sel[0] if sel else None

    # The default render (tables of --default-photons): its multiple scattering between voxels, as its image says.
    defaults = [x for x in rows if x["method"] == "fast" and x["value"] == args.default_photons]
    how = str(defaults[0].get("multiple_scattering", "")) if defaults else ""
    diffuse_default = how.startswith("diffuse")
    m = re.search(r"([0-9]+) photons per band", how)
    default_field = (f"the diffuse field of {int(m.group(1))} photons per band" if m
                     else "the diffuse field at its default photons")
    regenerate = "/usr/bin/python3 validation/accuracy_report.py --nebula build/bin/nebula" + (
        f" --backend {args.backend}" if args.backend != "cpu" else "")
    out = []
    out.append("<!-- Generated by validation/accuracy_report.py: the tables and plots are generated (edit the "
               "script, not them); the findings blocks between their markers are written by hand here and kept "
               "when the page is regenerated. -->")
    out.append("# Accuracy: the fast renderer and the path tracer against the ground truth\n")
    out.append(f"Regenerate: `{regenerate}` "
               f"(this run: {elapsed / 60:.1f} min on {machine}, backend {args.backend}, truth with "
               f"{args.transmittance} transmittance and "
               f"{'equiangular (MIS)' if args.equiangular else 'collision-only'} next-event estimation"
               + (f", up to {args.truth_strata} x {args.truth_strata} pixel-area strata per pixel (the pixel's mean, "
                  "as the fast renderer's pixels)" if args.truth_strata > 1 else ", one ray through each pixel's "
                  "centre") + "; "
               f"images {args.note}). The physics of the truth and how to read these numbers: "
               "[docs/truth.md](truth.md).\n")
    out.append("The fast renderer (`nebula render`) adds the light scattered *between* voxels, by default, from "
               "the diffuse field: a field of that light baked by photons from the stars (scene key "
               "`render.multiple_scattering = \"diffuse\"`, photons per band `render.diffuse_photons`; "
               "[docs/diffuse.md](diffuse.md)). The 2005 "
               "paper's multi-resolution pyramid is kept as the alternative (`--levels N`, "
               "[docs/pyramid.md](pyramid.md)), and `render.multiple_scattering = \"none\"` leaves that light out "
               "(single scattering and the scattering inside each voxel, from the tables). The rows: "
               "**fast**, **fast smooth**, **fast table**: "
               + (f"the default, {default_field}, " if diffuse_default else "the renderer's default, ")
               + "as the table's photons per row, the smooth mode's step and the table's τ × μ resolution vary; "
               "**fast diffuse**: the diffuse field's photons per band, at the default tables; "
               "**fast none**: no multiple scattering between voxels; **fast pyramid**: the pyramid with "
               f"{level_range(rows)} instead of the diffuse field.\n")
    out.append("Columns, per image against the reference (mean over bands B, V, R; `nebula compare`): "
               "**rel L1**, **rel L2** over pixels with signal (reference above 10⁻³ of its peak); "
               "**worst 1%**: 99th percentile of the per-pixel relative error; **bias**: Σ(A−B)/ΣB; "
               "**noise**: the relative L2 the noise of both images alone gives; **excess**: the L2 error beyond "
               "that noise, √max(0, Σ(A−B)² − Σvar)/√ΣB², the fast method's own error with the reference's "
               "noise taken out. Times (backend "
               f"{args.backend}): fast = the stars' bake + the diffuse field's bake or the pyramid's coarser "
               "levels + the march (tables cached; generation times below), truth = tracing.\n")
    out.append("![time against error](images/accuracy_time_vs_error.png)\n")
    out.append("Dotted line: the reference's own noise level (relative L2). Below it an error cannot be "
               "resolved; `excess` is clamped at 10⁻⁴ in the plot. Beside the points: the diffuse field's photons "
               "per band (green), the pyramid's levels (purple).\n")
    out.append("![truth convergence](images/accuracy_truth_convergence.png)\n")
    if not r.has_levels:
        out.append("*Pyramid levels: not measured. This build's `nebula render` has no `--levels` option; the "
                   "script measures them automatically when it has.*\n")
    out.append(f"Table generation ({backend_name(args.backend)}, one-off, cached by the renderer): " +
               ", ".join(f"{k}: {v:.1f} s" for k, v in table_times.items()) + ".\n")

    out.append("## Where the fast renderer is biased, measured\n")
    out.append("The fast renderer at its defaults (exact traversal, tables of "
               f"{args.default_photons:g} photons per row, uniform-θ, "
               + (f"{default_field} for the light scattered between voxels" if diffuse_default else
                  f"multiple scattering between voxels: {how or 'not recorded'}")
               + ") against the truth; bias = Σ(fast − truth)/Σtruth with its standard error from the truth's "
               "variance image (mean over bands), and the L2 error beyond the truth's noise. The last columns: "
               "the path tracer limited to single scattering (`--max-orders 1`) against the truth, the fast image "
               "against that, and the same for the fast renderer without multiple scattering between voxels "
               "(`none`: what the tables alone add to single scattering):\n")
    out.append("| scene | bias | ± | excess rel L2 | worst 1% | truth noise (rel L2) | single scattering "
               "/ truth | fast / single scattering | none: bias | none / single scattering |")
    out.append("|---|---|---|---|---|---|---|---|---|---|")
    for x in defaults:
        ref = [y for y in rows if y["scene"] == x["scene"] and y["method"] == "truth (reference)"][0]
        ss = one(x["scene"], "truth orders", 1)
        none = one(x["scene"], "fast none", "none")
        # Sums over the reference's signal pixels: sum(ss)/sum(truth) = 1 + bias_ss.
        ss_text = (f"{1 + ss['bias']:.3f} | {(1 + x['bias']) / (1 + ss['bias']):.3f}" if ss else "— | —")
        none_text = f"{100 * none['bias']:+.1f}%" if none else "—"
        none_text += f" | {(1 + none['bias']) / (1 + ss['bias']):.3f}" if none and ss else " | —"
        out.append(f"| {x['scene']} | {100 * x['bias']:+.1f}% | {100 * x['bias_stderr']:.1f}% | "
                   f"{x['rel_l2_excess']:.3g} | {x['worst_1pct']:.3g} | {ref['noise_rel_l2'] / np.sqrt(2):.3g} | "
                   f"{ss_text} | {none_text} |")
    out.append("")
    out.append(findings_block("findings", findings))

    photons = sorted({x["value"] for x in rows if x["method"] == "fast diffuse"})
    if photons:
        out.append("## The diffuse field against the truth\n")
        out.append("The defaults above with the diffuse field baked from each number of photons per band "
                   "(`--set render.diffuse_photons=N`), beside no multiple scattering between voxels (`none`). "
                   "Per cell: bias, then the L2 error beyond the truth's noise, then the time (the bake included).\n")
        out.append("| scene | none | " + " | ".join(f"{n} photons" for n in photons) + " |")
        out.append("|---|---|" + "---|" * len(photons))
        for scene in scenes:
            cells = [cell(one(scene, "fast none", "none"), "time")]
            cells += [cell(one(scene, "fast diffuse", n), "time") for n in photons]
            out.append(f"| {scene} | " + " | ".join(cells) + " |")
        out.append("")
        out.append(findings_block("diffuse findings", findings))
    elif findings["diffuse findings"]:
        out.append("## The diffuse field against the truth\n")
        out.append("*Not measured in this run; the findings below are from an earlier run.*\n")
        out.append(findings_block("diffuse findings", findings))

    if r.has_levels:
        levels = sorted({x["value"] for x in rows if x["method"] == "fast pyramid"})
        out.append("## The pyramid against the truth\n")
        out.append("The same defaults with the 2005 paper's multi-resolution pyramid ([docs/pyramid.md](pyramid.md)) "
                   "in place of the diffuse field: 0 levels (no multiple scattering between voxels, `none`), "
                   f"{level_range(rows)}, and last the default, the diffuse field. "
                   "Per cell: bias, then the L2 error beyond the truth's noise, then the worst 1% of pixels.\n")
        out.append("| scene | 0 levels (none) | " + " | ".join(f"{n} level{'s' if n != 1 else ''}" for n in levels) +
                   (" | diffuse field (default) |" if diffuse_default else " | default |"))
        out.append("|---|---|" + "---|" * len(levels) + "---|")
        for scene in scenes:
            cells = [cell(one(scene, "fast none", "none"))]
            cells += [cell(one(scene, "fast pyramid", n)) for n in levels]
            cells.append(cell(one(scene, "fast", args.default_photons)))
            out.append(f"| {scene} | " + " | ".join(cells) + " |")
        out.append("")
        out.append(findings_block("pyramid findings", findings))
    elif findings["pyramid findings"]:
        # Not measured in this run: keep the hand-written block rather than lose it.
        out.append("## The pyramid against the truth\n")
        out.append("*Not measured in this run (no `--levels`); the findings below are from an earlier run.*\n")
        out.append(findings_block("pyramid findings", findings))
    for scene in dict.fromkeys(x["scene"] for x in rows):
        out.append(f"## {scene}\n")
        out.append("| method | knob | value | time s | rel L1 | rel L2 | worst 1% | bias | noise | excess |")
        out.append("|---|---|---|---|---|---|---|---|---|---|")
        for x in rows:
            if x["scene"] != scene:
                continue
            out.append(f"| {table_label(rows, x['method'])} | {x['knob']} | {x['value']} | {x['seconds']:.3g} | "
                       f"{x['rel_l1']:.3g} | {x['rel_l2']:.3g} | {x['worst_1pct']:.3g} | {x['bias']:+.3g} | "
                       f"{x['noise_rel_l2']:.3g} | {x['rel_l2_excess']:.3g} |")
        out.append("")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(path + ".tmp", path)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--nebula", default=os.path.join(ROOT, "build", "bin", "nebula"))
    p.add_argument("--work", default=os.path.join(ROOT, "build", "accuracy"))
    p.add_argument("--backend", default="cpu")
    p.add_argument("--transmittance", default="exact",
                   help="the truth's next-event transmittance: exact (voxel sum; 2x faster on 32^3 grids at equal "
                        "noise, measured) or ratio")
    p.add_argument("--equiangular", action="store_true",
                   help="the truth with equiangular next-event estimation (MIS; for stars inside dust)")
    p.add_argument("--scenes", nargs="*", default=SCENES)
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--truth-spp", type=int, nargs="*", default=[4, 16, 64, 256])
    p.add_argument("--orders-spp", type=int, default=256, help="spp of the single- and double-scattering runs")
    p.add_argument("--photons", type=int, nargs="*", default=[1000, 3000, 10000, 30000])
    p.add_argument("--default-photons", type=int, default=30000)
    p.add_argument("--steps", type=float, nargs="*", default=[1.0, 0.5, 0.25])
    p.add_argument("--resolutions", nargs="*", default=["100x18", "100x72", "1000x18", "1000x72"])
    p.add_argument("--table-photons-res", type=int, default=10000, help="photons per row of the resolution tables")
    p.add_argument("--levels", type=int, nargs="*", default=[1, 2, 3, 4],
                   help="pyramid levels (--levels N: the 2005 pyramid instead of the diffuse field)")
    p.add_argument("--diffuse-photons", type=int, nargs="*", default=[16384, 65536, 262144, 1048576],
                   help="photons per band of the diffuse field (--set render.diffuse_photons=N), at the default "
                        "tables")
    p.add_argument("--machine", default="", help="how the report names the machine")
    p.add_argument("--note", default="64x64, grids 32^3")
    p.add_argument("--docs", default=os.path.join(ROOT, "docs"))
    p.add_argument("--truth-strata", type=int, default=4,
                   help="the truths' pixel-area strata per side, at most (render.samples_per_pixel; 1: the pixel's "
                        "centre ray). The fast renderer's pixels stand for their area's mean near a star")
    p.add_argument("--from-json", default="", help="rewrite the plots and the page from a run's results.json")
    args = p.parse_args()
    args.resolutions = [tuple(int(v) for v in s.split("x")) for s in args.resolutions]
    if args.truth_strata < 1:
        raise SystemExit(f"--truth-strata: must be 1 or more, got {args.truth_strata}")
    start = time.time()
    if args.from_json:
        # Only the plots and the page, from a finished run's results.
        with open(args.from_json) as f:
            saved = json.load(f)
        r = argparse.Namespace(has_levels=saved["has_levels"])
        # What the run measured with (results from before these were saved: the command line's).
        args.truth_strata = 1  # runs from before the strata: centre rays
        for key, value in saved.get("settings", {}).items():
            setattr(args, key, value)
        plot(saved["rows"], os.path.join(args.docs, "images"), args.backend)
        write_markdown(saved["rows"], args, r, saved["table_times"], os.path.join(args.docs, "accuracy.md"),
                       saved["elapsed"])
        return 0
    write_densities(os.path.join(ROOT, "validation", "scenes"))
    r = Runner(args)
    table_times = {}
    for tau_bins, mu_bins in args.resolutions:
        out = os.path.join(r.work, f"table_{tau_bins}x{mu_bins}.h5")
        table_times[f"{tau_bins}x{mu_bins} at {args.table_photons_res:g} photons/row"] = r.tabulate(
            out, args.table_photons_res, tau_bins, mu_bins)
    rows = []
    for name in args.scenes:
        print(f"{name} ...", flush=True)
        study(r, name, args, rows, None)
    with open(os.path.join(r.work, "results.json"), "w") as f:
        settings = {k: getattr(args, k) for k in ("backend", "transmittance", "equiangular", "default_photons",
                                                   "truth_strata")}
        json.dump(dict(rows=rows, table_times=table_times, has_levels=r.has_levels, settings=settings,
                       elapsed=time.time() - start), f, indent=1)
    plot(rows, os.path.join(args.docs, "images"), args.backend)
    write_markdown(rows, args, r, table_times, os.path.join(args.docs, "accuracy.md"), time.time() - start)
    print(f"wrote {os.path.join(args.docs, 'accuracy.md')} ({(time.time() - start) / 60:.1f} min)")


if __name__ == "__main__":
    sys.exit(main())
