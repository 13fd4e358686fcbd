#!/usr/bin/env python3
"""The spectral system's study (issue 14, docs/spectral.md): Barres (2023)
Figs. 4.1-4.4 and Tables 4.1-4.4 in our terms, with plots in docs/images.

    python3 validation/spectral_study.py [--nebula build/bin/nebula] [--backend cpu|cuda]
                                         [--quick] [--out docs/images] [--json study.json]

1. The greedy basis on the report's settings (family e^(-a/lambda), a in [0, 1],
   absolute L2 error, first element the constant): each member's error against
   its projection with the best second element (Fig. 4.1-4.2), and the largest
   error per basis size on [0.25, 1] and [1, 10] um (Figs. 4.3-4.4). Computed
   here with numpy, independently of the C++ (spectral_tests prints the C++
   numbers; they agree to the digits shown).
2. `nebula bench spectral` on the report's kind of scene (fBm noise cube, one
   star, the report's C_T / lambda so that the analytic integral runs): time and
   per-pixel error of every method against the double integral (Tables 4.1-4.2,
   Fig. 4.5), error and time against basis size.
3. The same with six stars of different spectra (Tables 4.3-4.4): the
   light-density basis and the voxel-light method against the double integral
   and against one star (also alternated in one run: the bench's star_ratios).
4. Our Fig. 12 scene (scenes/fig12_reference.toml, the scene's CCM89 law).
Any python3 with numpy and matplotlib; the GPU machine runs it with --backend cuda.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def greedy(lam, family, n):
    """Algorithm 2 with modified Gram-Schmidt, absolute L2 (trapezoid weights):
    returns chosen indices and the per-member error after each size."""
    w = np.full(lam.size, lam[1] - lam[0])
    w[0] *= 0.5
    w[-1] *= 0.5
    residual = family.copy()
    errors = [np.sqrt((residual ** 2 * w).sum(axis=1))]
    chosen = []
    for k in range(n):
        pick = 0 if k == 0 else int(np.argmax(errors[-1]))
        phi = residual[pick] / errors[-1][pick]
        residual -= np.outer((residual * phi * w).sum(axis=1), phi)
        chosen.append(pick)
        errors.append(np.sqrt(np.maximum((residual ** 2 * w).sum(axis=1), 0)))
    return chosen, errors


def basis_figures(out, summary):
    a = np.linspace(0.0, 1.0, 101)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    for (lo, hi), ax in zip([(0.25, 1.0), (1.0, 10.0)], axes[1:]):
        lam = np.linspace(lo, hi, 2001)
        family = np.exp(-np.outer(a, 1.0 / lam))
        chosen, errors = greedy(lam, family, 5)
        largest = [float(e.max()) for e in errors]
        summary["basis_%g_%g" % (lo, hi)] = {"chosen_a": [float(a[c]) for c in chosen], "largest_error": largest}
        ax.semilogy(range(len(largest)), largest, "o-")
        for n, e in enumerate(largest):
            ax.annotate("%.2g" % e, (n, e), textcoords="offset points", xytext=(4, 4), fontsize=8)
        ax.set_xlabel("basis elements")
        ax.set_ylabel("largest L2 error over the family")
        ax.set_title("Fig. 4.%d: error per size, [%g, %g] um" % (3 if lo < 1 else 4, lo, hi))
        ax.grid(True, which="both", alpha=0.3)
        if lo < 1:
            ax0 = axes[0]
            for n in (1, 2, 3):
                ax0.plot(a, errors[n], label="%d element(s)%s" % (n, "" if n == 1 else " (+ a = %.2f)" % a[chosen[n - 1]]))
            ax0.set_xlabel("family member a (e^(-a/lambda))")
            ax0.set_ylabel("L2 error against its projection")
            ax0.set_title("Figs. 4.1-4.2: members on [0.25, 1] um")
            ax0.legend(fontsize=8)
            ax0.grid(True, alpha=0.3)
    fig.tight_layout()
    path = os.path.join(out, "spectral_basis.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def bench(nebula, args, extra):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "bench.json")
        cmd = [nebula, "bench", "spectral", "--backend", args.backend, "--json", path] + extra
        print("$", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
        with open(path) as f:
            return json.load(f)


def rows_of(result, method, norm="relative"):
    run = result["runs"][0]
    return [r for r in run["rows"] if r["method"] == method and (method in ("double", "analytic") or r["norm"] == norm)]


def table(result):
    run = result["runs"][0]
    lines = ["%s, %d star(s), %dx%d, filters %s, attenuation %s; %s" % (
        result["scene"], result["stars"], result["width"], result["height"], result["filters"],
        result["attenuation"], run["device"]),
        "",
        "| method | ms | speed-up vs double M = %d (%.1f ms) | largest pixel error | 99th percentile | mean |" % (
            run["reference_wavelengths"], run["reference_ms"]),
        "| --- | ---: | ---: | ---: | ---: | ---: |"]
    for r in run["rows"]:
        name = r["method"]
        if r["method"] == "double":
            name += ", M = %d" % r["wavelengths"]
        elif r["method"] != "analytic":
            name += ", N = %d%s" % (r["basis"], "" if r["norm"] == "relative" else " (absolute)")
        lines.append("| %s | %.2f | %.1f | %.2e | %.2e | %.2e |" % (
            name, r["ms"], r["speedup"], r["max_err"], r["p99_err"], r["mean_err"]))
    return "\n".join(lines)


def size_plot(results, out):
    fig, (ax_e, ax_t) = plt.subplots(1, 2, figsize=(12, 4.2))
    for label, result in results:
        run = result["runs"][0]
        for method, norm, style in (("projection", "relative", "o-"), ("projection", "absolute", "s--"),
                                    ("light_density", "relative", "^-"), ("voxel_light", "relative", "v-")):
            rows = rows_of(result, method, norm)
            if not rows:
                continue
            n = [r["basis"] for r in rows]
            name = "%s: %s%s" % (label, method, "" if norm == "relative" else " (absolute, the report's)")
            ax_e.semilogy(n, [max(r["max_err"], 1e-7) for r in rows], style, label=name)
            ax_t.plot(n, [r["ms"] for r in rows], style, label=name)
        for r in rows_of(result, "double"):
            ax_t.axhline(r["ms"], color="grey", lw=0.6, alpha=0.5)
        ax_t.axhline(run["reference_ms"], color="k", lw=1, ls=":")
    ax_e.axhline(0.01, color="r", lw=1, ls=":", label="goal: 1% per pixel")
    ax_e.set_xlabel("basis elements N")
    ax_e.set_ylabel("largest relative error per pixel")
    ax_e.set_title("Error against basis size\n(reference: the double integral, M = 400)")
    ax_e.grid(True, which="both", alpha=0.3)
    ax_e.legend(fontsize=7)
    ax_t.set_xlabel("basis elements N")
    ax_t.set_ylabel("ms per frame")
    ax_t.set_yscale("log")
    ax_t.set_title("Time against basis size\n(grey: double M = 10..80; dotted: double M = 400)")
    ax_t.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    path = os.path.join(out, "spectral_error_time.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--nebula", default=os.path.join(ROOT, "build", "bin", "nebula"))
    p.add_argument("--backend", default="cpu", choices=["cpu", "cuda"])
    p.add_argument("--quick", action="store_true", help="small frames (the CPU of a laptop or CI)")
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "images"))
    p.add_argument("--json", default=None, help="write every number to this file")
    p.add_argument("--from-json", default=None, help="plot and print a --json file of an earlier run (no bench)")
    args = p.parse_args()
    if not args.from_json and not os.path.exists(args.nebula):
        sys.exit("spectral_study: no nebula binary at %s (build it, or give --nebula)" % args.nebula)
    os.makedirs(args.out, exist_ok=True)
    summary = {}
    print("wrote", basis_figures(args.out, summary))
    for key in ("basis_0.25_1", "basis_1_10"):
        print(key, summary[key])

    if args.from_json:
        with open(args.from_json) as f:
            summary.update(json.load(f))
        one, six, one_law, fig12 = (summary[k] for k in ("noise_one_star", "noise_six_stars", "noise_one_star_law", "fig12"))
    else:
        one, six, one_law, fig12 = run_benches(args)
    report(args, summary, one, six, one_law, fig12)


def run_benches(args):
    size, frame, repeats = ("48", "128", "2") if args.quick else ("96", "512", "3")
    noise = ["--size", size, "--width", frame, "--height", frame, "--repeats", repeats, "--tau", "4"]
    one = bench(args.nebula, args, noise + ["--stars", "1", "--attenuation", "inverse"])
    six = bench(args.nebula, args, noise + ["--stars", "6", "--attenuation", "law", "--quick"])
    one_law = bench(args.nebula, args, noise + ["--stars", "1", "--attenuation", "law", "--quick"])
    fig12_frame = "128" if args.quick else "512"
    fig12 = bench(args.nebula, args, ["--scene", os.path.join(ROOT, "scenes", "fig12_reference.toml"),
                                      "--width", fig12_frame, "--height", fig12_frame, "--repeats", repeats,
                                      "--attenuation", "law"])
    return one, six, one_law, fig12


def report(args, summary, one, six, one_law, fig12):
    summary.update({"noise_one_star": one, "noise_six_stars": six, "noise_one_star_law": one_law, "fig12": fig12})
    print("wrote", size_plot([("noise cube", one), ("Fig. 12", fig12)], args.out))
    for name, result in (("Tables 4.1-4.2 (noise cube, one star)", one), ("Tables 4.3-4.4 (six stars)", six),
                         ("one star, the law (the six-star run's baseline)", one_law), ("Fig. 12 scene", fig12)):
        print("\n### " + name + "\n")
        print(table(result))
    # Six spectra at the cost of one: the same method and basis, six stars against one.
    print("\n### six stars against one (same method, law attenuation)\n")
    print("| method | 1 star ms | 6 stars ms | ratio |")
    print("| --- | ---: | ---: | ---: |")
    for r6 in six["runs"][0]["rows"]:
        for r1 in one_law["runs"][0]["rows"]:
            if (r1["method"], r1["basis"], r1["wavelengths"], r1["norm"]) == (
                    r6["method"], r6["basis"], r6["wavelengths"], r6["norm"]):
                print("| %s N=%d M=%d | %.2f | %.2f | %.2f |" % (r6["method"], r6["basis"], r6["wavelengths"],
                                                              r1["ms"], r6["ms"], r6["ms"] / r1["ms"]))
    # The same, measured in one process with frames alternated (the six-star run's
    # `star_ratios`: each method with six stars against the first star alone).
    ratios = six["runs"][0].get("star_ratios", [])
    if ratios:
        print("\n### six stars against the first alone, frames alternated in one run (goal: ratio <= 1.1)\n")
        print("| method | 1 star ms | 6 stars ms | ratio |")
        print("| --- | ---: | ---: | ---: |")
        for r in ratios:
            print("| %s N=%d | %.2f | %.2f | %.3f |" % (r["method"], r["basis"], r["one_star_ms"], r["all_stars_ms"],
                                                     r["ratio"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
        print("wrote", args.json)


if __name__ == "__main__":
    main()
