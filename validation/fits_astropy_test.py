#!/usr/bin/env python3
"""Issue 16: a FITS image from `nebula render` read with astropy alone, as an astronomer would.

Renders a uniform dust sphere (scenes/uniform_sphere.toml, small) with an orthographic camera,
then checks from the FITS file only: the WCS maps pixels to sky offsets and back; BUNIT parses
with astropy.units; the keywords are numbers; and the radial surface-brightness profile, centred
and scaled by the WCS, puts the sphere where the scene (read back from the SCENE extension) says.
Usage: fits_astropy_test.py NEBULA SOURCE_DIR WORK_DIR. Exit 77 (a ctest skip) without astropy."""
import os
import subprocess
import sys
import tomllib


def main():
    try:
        import numpy as np
        from astropy import units as u
        from astropy.io import fits
        from astropy.wcs import WCS
    except ImportError as e:
        print(f"skip: astropy is not installed for {sys.executable} ({e}); scripts/test.sh installs it")
        return 77
    nebula, source, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    out = os.path.join(work, "sphere.fits")
    subprocess.run([nebula, "render", os.path.join(source, "scenes", "uniform_sphere.toml"), "-o", out, "--force",
                    "-q", "--backend", "cpu", "--table-photons", "3000", "--set", "camera.width=64",
                    "--set", "camera.height=64", "--set", "render.diffuse_photons=20000",
                    "--set", "camera.exposure=0.5"], check=True, capture_output=True)
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    with fits.open(out) as hdul:
        h = hdul[0].header
        data = hdul[0].data.astype(np.float64)  # [band][y][x], y up
        scene = tomllib.loads(bytes(hdul["SCENE"].data).decode())
    w = WCS(h)
    sky = w.sub([1, 2])  # the two image axes (the third counts the bands)

    # Keywords are numbers, the exposure recorded and not applied.
    check(isinstance(h["ALBEDO_V"], float) and isinstance(h["CAM_WIDTH"], int), "ALBEDO_V float, CAM_WIDTH int")
    check(h["EXPOSURE"] == 0.5, f"EXPOSURE = {h['EXPOSURE']} is the scene's camera.exposure")
    check(isinstance(h["PIVOT_NM_V"], float) and 500 < h["PIVOT_NM_V"] < 600, f"PIVOT_NM_V = {h['PIVOT_NM_V']}")
    bands = [h[f"BAND{i + 1}"] for i in range(h["NAXIS3"])]
    check(bands == ["B", "V", "R"], f"bands {bands}")

    # BUNIT parses, in astropy's generic and FITS unit formats.
    unit = u.Unit(h["BUNIT"], format="fits")
    check(unit == u.Unit("solLum") / u.pc ** 2 / u.sr and u.Unit(h["BUNIT"]) == unit, f"BUNIT {h['BUNIT']!r} -> {unit}")

    # WCS round trip and scale: the camera's width across the image.
    ny, nx = data.shape[1:]
    px = np.array([0.0, 10.3, nx - 1.0, 31.5]), np.array([0.0, 50.2, 7.0, 31.5])
    world = sky.pixel_to_world_values(*px)
    back = sky.world_to_pixel_values(*world)
    check(np.allclose(back, px, atol=1e-9), "pixel -> world -> pixel")
    edge = sky.pixel_to_world_values(nx - 0.5, 0)[0] - sky.pixel_to_world_values(-0.5, 0)[0]
    cam = scene["camera"]
    check(abs(edge - cam["ortho_width"]) < 1e-9 and w.wcs.cunit[0] == "pc",
          f"image width {edge} pc = camera.ortho_width {cam['ortho_width']}")

    # Radial profile of the V band about the sphere's centre on the sky, from the WCS alone.
    p = scene["density"]["procedural"]
    size = p["size_pc"]
    centre = np.array(p["star"]) * size  # bubble_offset 0: the sphere is centred on the star
    radius = p["bubble_radius"] * size
    look = np.array(cam["look_at"])
    yy, xx = np.mgrid[0:ny, 0:nx]
    ox, oy = sky.pixel_to_world_values(xx, yy)  # pc along the camera's right and up (+x, +y here)
    cx, cy = centre[0] - look[0], centre[1] - look[1]
    v = data[bands.index("V")]
    r = np.hypot(ox - cx, oy - cy)
    pixel = abs(w.wcs.cdelt[0])
    inside, outside = v[r < 0.8 * radius], v[r > radius + 2 * pixel]
    peak = v.max()
    check(outside.max() < 1e-3 * peak, f"outside the sphere (r > {radius:.2f} pc + 2 px): at most "
          f"{outside.max() / peak:.2e} of the peak")
    # Lit throughout (the star's light falls as 1/r^2 from the centre, so the inside is far from uniform).
    check(inside.min() > 1e-3 * peak, f"inside 0.8 R: at least {inside.min() / peak:.4f} of the peak")
    mx, my = (v * ox).sum() / v.sum(), (v * oy).sum() / v.sum()
    check(np.hypot(mx - cx, my - cy) < pixel, f"brightness centroid ({mx:.4f}, {my:.4f}) pc at the sphere's centre "
          f"({cx:.4f}, {cy:.4f}) within a pixel ({pixel:.4f} pc)")
    # The profile falls to nothing at the sphere's edge: half the light within the projected radius.
    edges = np.linspace(0, radius * 1.3, 14)
    profile = [v[(r >= a) & (r < b)].mean() for a, b in zip(edges[:-1], edges[1:])]
    print("radial profile (pc, V / peak): " + ", ".join(f"{0.5 * (a + b):.2f}:{m / peak:.3f}"
                                                        for a, b, m in zip(edges[:-1], edges[1:], profile)))
    last_lit = max(i for i, m in enumerate(profile) if m > 1e-3 * peak)
    check(edges[last_lit] < radius <= edges[last_lit + 1] + pixel,
          f"profile ends at the sphere's radius {radius:.2f} pc (last lit bin from {edges[last_lit]:.2f} pc)")

    print(f"{len(failures) == 0 and 'all' or len(failures)} checks {'passed' if not failures else 'failed'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
