#!/usr/bin/env python3
"""Writes data/filters/*.csv from the filter tables that ship as package data of
the PyPI packages speclite (SDSS) and astro-sedpy (HST, JWST). Only numbers are
taken, with their source; run once by hand in a throwaway venv:
  python3 -m venv /tmp/fv && /tmp/fv/bin/pip install speclite astro-sedpy
  /tmp/fv/bin/python scripts/import_filters.py data/filters
Each table is trimmed to the rows whose response reaches 1e-3 of its peak (one
row more on each side), thinned to at most one row per 5 angstrom where it is
finer (rows are kept, never interpolated), and normalised to a peak of 1."""
import os
import sys

import speclite
import sedpy

SPECLITE = os.path.join(os.path.dirname(speclite.__file__), "data", "filters")
SEDPY = os.path.join(os.path.dirname(sedpy.__file__), "data", "filters")

SDSS_SOURCE = ("Doi et al. (2010), AJ 139, 1628, Table 4 (doi:10.1088/0004-6256/139/4/1628): "
               "SDSS 2.5 m imager response through airmass 1.3")
ACS_SOURCE = "HST ACS/WFC system throughput (STScI ACS instrument team, retrieved 2017-02-06)"
WFC3_UVIS_SOURCE = "HST WFC3/UVIS chip 1 system throughput (STScI WFC3 instrument team)"
WFC3_IR_SOURCE = "HST WFC3/IR system throughput (STScI WFC3 instrument team)"
NIRCAM_SOURCE = ("JWST NIRCam filter+DBS+QE+OTE throughput, post-flight May 2024 (B. Hilbert, STScI, "
                 "photon-to-electron conversion efficiency)")

# (our file stem, scene name, package, file, source)
FILTERS = []
for b in "ugriz":
    FILTERS.append((f"sdss-{b}", f"sdss_{b}", "speclite", f"sdss2010-{b}.ecsv", SDSS_SOURCE))
for f in ["f435w", "f475w", "f555w", "f606w", "f625w", "f775w", "f814w"]:
    FILTERS.append((f"hst-acs-{f.upper()}", f.upper(), "sedpy", f"acs_wfc_{f}.par", ACS_SOURCE))
for f in ["f336w", "f475w", "f555w", "f606w", "f814w"]:
    FILTERS.append((f"hst-wfc3-{f.upper()}", "wfc3_" + f.upper(), "sedpy", f"wfc3_uvis_{f}.par", WFC3_UVIS_SOURCE))
for f in ["f105w", "f125w", "f160w"]:
    FILTERS.append((f"hst-wfc3-{f.upper()}", "wfc3_" + f.upper(), "sedpy", f"wfc3_ir_{f}.par", WFC3_IR_SOURCE))
for f in ["f070w", "f090w", "f115w", "f150w", "f200w", "f277w", "f356w", "f444w"]:
    FILTERS.append((f"jwst-nircam-{f.upper()}", f.upper(), "sedpy", f"jwst_{f}.par", NIRCAM_SOURCE))


def rows_of(package, name):
    path = os.path.join(SPECLITE if package == "speclite" else SEDPY, name)
    rows = []
    with open(path) as f:
        for line in f:
            cells = line.split()
            if not cells or line.startswith("#"):
                continue
            try:
                rows.append((float(cells[0]), float(cells[1])))
            except ValueError:
                continue  # the ecsv column names
    return rows


def main(out_dir):
    for stem, name, package, file, source in FILTERS:
        rows = rows_of(package, file)
        peak = max(r for _, r in rows)
        keep = [i for i, (_, r) in enumerate(rows) if r >= 1e-3 * peak]
        lo, hi = max(keep[0] - 1, 0), min(keep[-1] + 1, len(rows) - 1)
        rows = rows[lo:hi + 1]
        thinned, last = [], None
        for i, (w, r) in enumerate(rows):
            if last is None or w - last >= 5.0 or i == len(rows) - 1:
                thinned.append((w, r))
                last = w
        with open(os.path.join(out_dir, stem + ".csv"), "w") as out:
            out.write(f"# {name}: {source}; peak throughput {peak:.4g}, response normalised to a peak of 1\n")
            out.write(f"# numeric table as distributed with the {'speclite' if package == 'speclite' else 'astro-sedpy'}"
                      f" package ({package}/data/filters/{file}), trimmed below 1e-3 of the peak, rows at least 5 A apart\n")
            out.write("wavelength_angstrom,response\n")
            for w, r in thinned:
                out.write(f"{w:.6g},{r / peak:.6g}\n")
        print(name, stem, len(thinned), "rows", thinned[0][0], "-", thinned[-1][0], "A")


if __name__ == "__main__":
    main(sys.argv[1])
