#!/usr/bin/python3
"""Plot a multiple-scattering table P(tau, theta) from an HDF5 file as a PNG.

Left panel: polar plot of P against the scattering angle theta for a few
optical depths, mirrored into a full lobe (0 deg = forward, light enters from
the left).  Right panel: escaped scattered fraction /total (with a +-2 stderr
band) and the unscattered fraction against tau.  A text box lists the table's
attributes.

Usage:
    /usr/bin/python3 validation/plot_table.py TABLE.h5 -o OUT.png \
        [--tau 0.1 1 2 5 10] [--log]

Needs only Debian's python3-numpy, python3-matplotlib and python3-h5py.
"""

import argparse
import math
import os
import sys

PROG = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "plot_table.py"
DEFAULT_TAUS = (0.1, 0.5, 1.0, 2.0, 5.0, 10.0)
# Largest number of decades shown below the peak with --log.
LOG_DECADES = 6


class TableError(Exception):
    """A problem with the input table or the request; printed as one line."""


def fail(message, code=1):
    print(f"{PROG}: error: {message}", file=sys.stderr)
    sys.exit(code)


def warn(message):
    print(f"{PROG}: warning: {message}", file=sys.stderr)


def import_libraries():
    missing = []
    try:
        import numpy  # noqa: F401
    except ImportError:
        missing.append("python3-numpy")
    try:
        import matplotlib
        matplotlib.use("Agg")
    except ImportError:
        missing.append("python3-matplotlib")
    try:
        import h5py  # noqa: F401
    except ImportError:
        missing.append("python3-h5py")
    if missing:
        fail("missing Python packages for this interpreter: " + ", ".join(missing)
             + " (install with: apt-get install " + " ".join(missing) + ")")


# ----------------------------------------------------------------------------
# Reading the table

def decode_text(value):
    """Turns an HDF5 string attribute (fixed- or variable-length) into str."""
    import numpy as np
    if isinstance(value, np.ndarray):
        if value.size != 1:
            return ", ".join(decode_text(v) for v in value.ravel())
        value = value.ravel()[0]
    if isinstance(value, (bytes, np.bytes_)):
        value = bytes(value).decode("utf-8", errors="replace")
    return str(value).rstrip("\x00").strip()


def scalar_attribute(value):
    import numpy as np
    if isinstance(value, np.ndarray):
        if value.size != 1:
            raise ValueError("not a scalar")
        value = value.ravel()[0]
    return value


def read_table(path):
    """Returns a dict with the datasets and attributes, or raises TableError."""
    import numpy as np
    import h5py

    if not os.path.exists(path):
        raise TableError(f"{path}: no such file")
    if os.path.isdir(path):
        raise TableError(f"{path}: is a directory, not an HDF5 table")
    if not os.access(path, os.R_OK):
        raise TableError(f"{path}: permission denied")
    try:
        is_hdf5 = h5py.is_hdf5(path)
    except OSError as e:
        raise TableError(f"{path}: cannot read ({e.strerror or e})")
    if not is_hdf5:
        raise TableError(f"{path}: not an HDF5 file")

    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise TableError(f"{path}: cannot open as HDF5 ({str(e).splitlines()[0]})")

    with f:
        def dataset(name, ndim):
            if name not in f:
                raise TableError(f"{path}: /{name}: missing dataset")
            node = f[name]
            if not isinstance(node, h5py.Dataset):
                raise TableError(f"{path}: /{name}: is not a dataset")
            if node.dtype.kind not in "fiu":
                raise TableError(f"{path}: /{name}: expected numbers, found type {node.dtype}")
            if node.ndim != ndim:
                raise TableError(f"{path}: /{name}: expected {ndim}-D, found shape {node.shape}")
            try:
                return np.asarray(node[()], dtype=np.float64)
            except (OSError, ValueError) as e:
                raise TableError(f"{path}: /{name}: read error ({e})")

        t = {
            "P": dataset("P", 2),
            "P_stderr": dataset("P_stderr", 2),
            "tau": dataset("tau", 1),
            "mu_edges": dataset("mu_edges", 1),
            "mu": dataset("mu", 1),
            "total": dataset("total", 1),
            "total_stderr": dataset("total_stderr", 1),
            "unscattered": dataset("unscattered", 1),
        }

        attrs = {}
        for name in ("albedo", "g"):
            if name not in f.attrs:
                warn(f"{path}: attribute {name} missing")
                attrs[name] = None
                continue
            try:
                attrs[name] = float(scalar_attribute(f.attrs[name]))
            except (TypeError, ValueError):
                raise TableError(f"{path}: attribute {name}: expected a number")
        if "photons_per_row" in f.attrs:
            try:
                attrs["photons_per_row"] = int(scalar_attribute(f.attrs["photons_per_row"]))
            except (TypeError, ValueError):
                raise TableError(f"{path}: attribute photons_per_row: expected an integer")
        else:
            warn(f"{path}: attribute photons_per_row missing")
            attrs["photons_per_row"] = None
        for name in ("illumination", "mu_binning", "phase", "geometry", "rng", "generator"):
            if name in f.attrs:
                try:
                    attrs[name] = decode_text(f.attrs[name])
                except (OSError, TypeError, ValueError):
                    raise TableError(f"{path}: attribute {name}: unreadable string")
            else:
                if name in ("illumination", "mu_binning"):
                    warn(f"{path}: attribute {name} missing")
                attrs[name] = None
        t["attrs"] = attrs

    check_shapes(path, t)
    return t


def check_shapes(path, t):
    import numpy as np
    n_tau, n_mu = t["P"].shape
    if n_tau < 1 or n_mu < 1:
        raise TableError(f"{path}: /P: empty ({n_tau} x {n_mu})")
    expected = {
        "P_stderr": (n_tau, n_mu),
        "tau": (n_tau,),
        "mu": (n_mu,),
        "mu_edges": (n_mu + 1,),
        "total": (n_tau,),
        "total_stderr": (n_tau,),
        "unscattered": (n_tau,),
    }
    for name, shape in expected.items():
        if t[name].shape != shape:
            raise TableError(f"{path}: /{name}: shape {t[name].shape} does not match "
                             f"/P {t['P'].shape} (expected {shape})")
    tau = t["tau"]
    if not np.all(np.isfinite(tau)):
        raise TableError(f"{path}: /tau: contains non-finite values")
    if n_tau > 1 and not np.all(np.diff(tau) > 0):
        raise TableError(f"{path}: /tau: not strictly ascending")
    mu = t["mu"]
    if not np.all(np.isfinite(mu)) or np.any(np.abs(mu) > 1 + 1e-9):
        raise TableError(f"{path}: /mu: values outside [-1, 1]")
    edges = t["mu_edges"]
    if not np.all(np.isfinite(edges)) or not np.all(np.diff(edges) > 0):
        raise TableError(f"{path}: /mu_edges: not strictly ascending")


# ----------------------------------------------------------------------------
# Choosing rows

def choose_rows(path, tau, requested):
    """Maps the requested tau values to (row, tau) pairs, nearest row first come.

    requested is None for the default list, which is silently clipped to the
    axis; explicit values outside [tau_min, tau_max] raise TableError.
    """
    import numpy as np
    lo, hi = float(tau[0]), float(tau[-1])
    # Half a row of slack so that e.g. 10 matches an axis ending at 9.99999.
    slack = 0.5 * (hi - lo) / (len(tau) - 1) if len(tau) > 1 else 0.0
    if requested is None:
        wanted = [v for v in DEFAULT_TAUS if lo - slack <= v <= hi + slack]
        if not wanted:
            wanted = [hi]
    else:
        wanted = []
        for v in requested:
            if not math.isfinite(v) or v < lo - slack or v > hi + slack:
                raise TableError(f"{path}: /tau: requested tau {v:g} is outside the "
                                 f"table's axis [{lo:g}, {hi:g}]")
            wanted.append(v)
    rows = []
    for v in wanted:
        row = int(np.argmin(np.abs(tau - v)))
        if row in (r for r, _ in rows):
            warn(f"tau {v:g} maps to row {row} (tau = {tau[row]:g}), already plotted")
            continue
        rows.append((row, float(tau[row])))
    return rows


# ----------------------------------------------------------------------------
# Plotting

def format_number(v, digits=3):
    return "?" if v is None else f"{v:.{digits}g}"


def lobe(theta, values, step=math.radians(0.5)):
    """Mirrors a curve over theta in [0, pi] into a closed full-circle lobe.

    The bin-centre values are extended flat to theta = 0 and pi (the end bins
    cover those directions) and resampled every `step` radians, so that the
    segments follow the polar grid instead of cutting straight across it.
    """
    import numpy as np
    order = np.argsort(theta)
    th, v = theta[order], values[order]
    th = np.concatenate([[0.0], th, [np.pi]])
    v = np.concatenate([v[:1], v, v[-1:]])
    fine = np.linspace(0.0, np.pi, int(math.ceil(np.pi / step)) + 1)
    r = np.interp(fine, th, v)
    # Keep gaps where the table has non-finite values.
    bad = np.interp(fine, th, (~np.isfinite(v)).astype(float)) > 0
    r[bad] = np.nan
    angles = np.concatenate([fine, 2 * np.pi - fine[::-1][1:]])
    radii = np.concatenate([r, r[::-1][1:]])
    return angles, radii


def draw_polar(ax, t, rows, use_log, colors, path):
    import numpy as np
    theta = np.arccos(np.clip(t["mu"], -1.0, 1.0))
    P = t["P"]
    se = np.where(np.isfinite(t["P_stderr"]), t["P_stderr"], 0.0)
    picked = np.array([P[r] for r, _ in rows])

    if use_log:
        positive = picked[np.isfinite(picked) & (picked > 0)]
        if positive.size == 0:
            raise TableError(f"{path}: /P: the chosen rows have no positive values to plot with --log")
        peak = math.log10(positive.max())
        bottom = max(math.floor(math.log10(positive.min())), math.ceil(peak) - LOG_DECADES)
        top = peak + 0.05 * (peak - bottom)  # a little room outside the peak
        if top - bottom < 0.5:
            top = bottom + 1.0
        floor = 10.0 ** bottom

        def radius(v):
            v = np.where(np.isfinite(v) & (v > 0), v, floor)
            return np.log10(np.maximum(v, floor) / floor)
    else:
        def radius(v):
            return np.where(np.isfinite(v), np.maximum(v, 0.0), np.nan)

    for (row, tau_value), color in zip(rows, colors):
        a, r = lobe(theta, radius(P[row]))
        _, r_lo = lobe(theta, radius(P[row] - 2 * se[row]))
        _, r_hi = lobe(theta, radius(P[row] + 2 * se[row]))
        ax.fill_between(a, r_lo, r_hi, color=color, alpha=0.18, linewidth=0)
        ax.plot(a, r, color=color, linewidth=1.8, label=f"τ = {tau_value:.3g}")

    ax.set_theta_zero_location("E")
    ax.set_theta_direction(1)
    degrees = np.arange(0, 360, 30)
    ax.set_thetagrids(degrees, [f"{min(d, 360 - d)}°" for d in degrees])
    ax.set_rlabel_position(165)
    if use_log:
        ax.set_ylim(0, top - bottom)
        # One ring per decade; the centre (the floor itself) gets no label.
        rings = np.arange(1, math.floor(top - bottom) + 1)
        ax.set_rgrids(rings, [f"$10^{{{bottom + d}}}$" for d in rings], fontsize=8)
        scale_note = f"log radial scale, P < $10^{{{bottom}}}$ drawn at the centre"
    else:
        ax.set_ylim(0, None)
        ax.tick_params(axis="y", labelsize=8)
        scale_note = "linear radial scale"
    ax.tick_params(axis="x", labelsize=9)
    ax.grid(True, alpha=0.4)
    ax.set_axisbelow(False)  # radial labels above the curves (grid stays faint)
    ax.set_title("P per steradian per voxel face area (shaded: ±2 stderr)\n"
                 f"{scale_note}", fontsize=10, y=1.07)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.06), fontsize=9, framealpha=0.9,
              title="nearest row", title_fontsize=9)

    # Incident-light arrow on the left, pointing towards 0 deg (forward).
    ax.annotate("", xy=(-0.09, 0.5), xytext=(-0.28, 0.5), xycoords="axes fraction",
                arrowprops=dict(arrowstyle="-|>", lw=2.2, color="goldenrod"),
                annotation_clip=False)
    ax.text(-0.185, 0.53, "light comes\nfrom the left", transform=ax.transAxes,
            ha="center", va="bottom", fontsize=9, color="saddlebrown")
    ax.text(0.5, -0.1, "θ = scattering angle; 0° = forward (incident direction, to the right); "
            "lower half mirrors the upper", transform=ax.transAxes, ha="center", va="top",
            fontsize=8.5, color="0.25")


def draw_totals(ax, t, rows, colors):
    import numpy as np
    tau = t["tau"]
    total = t["total"]
    se = np.where(np.isfinite(t["total_stderr"]), t["total_stderr"], 0.0)
    ax.fill_between(tau, total - 2 * se, total + 2 * se, color="tab:blue", alpha=0.25,
                    linewidth=0, label="±2 stderr")
    marker = "o" if len(tau) <= 40 else None
    ax.plot(tau, total, color="tab:blue", linewidth=1.8, marker=marker, markersize=3,
            label="scattered, escaped (/total)")
    ax.plot(tau, t["unscattered"], color="tab:gray", linewidth=1.6, linestyle="--",
            label="unscattered (/unscattered)")
    for (_, tau_value), color in zip(rows, colors):
        ax.axvline(tau_value, color=color, linewidth=0.9, linestyle=":", alpha=0.9)
    ax.set_xlim(tau[0], tau[-1] if tau[-1] > tau[0] else tau[0] + 1)
    ax.set_ylim(0, max(1.0, float(np.nanmax(np.concatenate([total + 2 * se, t["unscattered"]]))) * 1.02))
    ax.set_xlabel("τ (scattering optical depth per voxel edge)")
    ax.set_ylabel("fraction of incident light")
    ax.set_title("Escaped fractions (dotted lines: τ rows in the polar plot)", fontsize=10)
    ax.grid(True, alpha=0.35)
    ax.legend(loc="upper right", fontsize=9, framealpha=0.9)


def shorten(text, width=24, keep_end=False):
    """Cuts text to `width` characters with an ellipsis (keeps the end if asked)."""
    text = " ".join(text.split())
    if len(text) <= width:
        return text
    return "…" + text[-(width - 1):] if keep_end else text[:width - 1] + "…"


def info_text(t, path):
    a = t["attrs"]
    photons = a["photons_per_row"]
    lines = [
        ("file", shorten(os.path.basename(path), keep_end=True)),
        ("albedo a", format_number(a["albedo"], 4)),
        ("g", format_number(a["g"], 4)),
        ("illumination", shorten(a["illumination"] or "?")),
        ("μ binning", shorten(a["mu_binning"] or "?")),
        ("photons / row", "?" if photons is None else f"{photons:,}"),
        ("τ rows", f"{len(t['tau'])} ({t['tau'][0]:g} to {t['tau'][-1]:g})"),
        ("μ bins", f"{len(t['mu'])}"),
    ]
    for name in ("phase", "geometry", "rng", "generator"):
        if a.get(name):
            lines.append((name, shorten(a[name])))
    width = max(len(k) for k, _ in lines)
    return "\n".join(f"{k.ljust(width)}  {v}" for k, v in lines)


def make_figure(t, rows, use_log, path):
    import matplotlib.pyplot as plt

    # Fixed placement in figure fractions (16 x 7 in): the polar plot is
    # square, its legend sits to its right, then the totals and the text box.
    fig = plt.figure(figsize=(16, 7), dpi=100)
    bottom, height = 0.12, 0.68
    polar_width = height * 7 / 16
    cmap = plt.get_cmap("viridis")
    n = len(rows)
    colors = [cmap(0.9 * i / max(n - 1, 1)) for i in range(n)]

    polar = fig.add_axes([0.095, bottom, polar_width, height], projection="polar")
    draw_polar(polar, t, rows, use_log, colors, path)
    totals = fig.add_axes([0.515, bottom, 0.255, height])
    draw_totals(totals, t, rows, colors)
    box = fig.add_axes([0.795, bottom, 0.195, height])
    box.axis("off")
    box.text(0.0, 0.98, info_text(t, path), transform=box.transAxes, ha="left", va="top",
             family="monospace", fontsize=8.5,
             bbox=dict(boxstyle="round,pad=0.6", facecolor="whitesmoke", edgecolor="0.6"))

    # Radial labels sit over the curves: give them a light background (after
    # a draw, so that the tick objects are the final ones).
    fig.canvas.draw()
    for tick in polar.yaxis.get_major_ticks():
        tick.label1.set_bbox(dict(facecolor="white", alpha=0.75, edgecolor="none", pad=0.5))
        tick.label1.set_zorder(5)

    a = t["attrs"]
    beam = a["illumination"] or "unknown"
    fig.suptitle(f"P(τ, θ): a = {format_number(a['albedo'])}, g = {format_number(a['g'])}, "
                 f"{beam} beam", fontsize=15, y=0.975)
    return fig


def write_png(fig, out):
    directory = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(directory):
        raise TableError(f"{out}: output directory {directory} does not exist")
    tmp = out + ".tmp"
    try:
        fig.savefig(tmp, format="png", dpi=100)
        os.replace(tmp, out)
    except OSError as e:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise TableError(f"{out}: cannot write ({e.strerror or e})")
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Plot a multiple-scattering table P(tau, theta) (HDF5) as a PNG: "
                    "polar lobes for a few tau values plus the escaped fractions.")
    parser.add_argument("table", help="HDF5 table written by the tabulator")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.png",
                        help="PNG to write (written to OUT.png.tmp, then renamed)")
    parser.add_argument("--tau", type=float, nargs="+", metavar="TAU",
                        help="tau values to plot (nearest row each); default "
                             + " ".join(f"{v:g}" for v in DEFAULT_TAUS)
                             + ", clipped to the table's axis")
    parser.add_argument("--log", action="store_true",
                        help="logarithmic radial scale in the polar plot")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    import_libraries()
    try:
        table = read_table(args.table)
        rows = choose_rows(args.table, table["tau"], args.tau)
        fig = make_figure(table, rows, args.log, args.table)
        write_png(fig, args.output)
    except TableError as e:
        fail(str(e))
    return 0


if __name__ == "__main__":
    sys.exit(main())
