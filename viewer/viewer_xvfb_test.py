#!/usr/bin/env python3
"""nebula-view's real window under Xvfb with Mesa (ctest viewer.xvfb).

It starts and renders; the window's own pixels equal the screenshot PNG; a
scripted edit (albedo 0.6 -> 0.9) brightens the dust in the window's pixels and
in the science screenshot; the saved scene re-renders with `nebula render` to
the same image; the fisheye shows its dome circle; a bad --set is one line.
On an axial scene: a scripted --paint of dust brightens the nebula where the
dust went, the saved scene (with its painted map) re-renders to the same
image, the map file loads back, erasing everything leaves a black frame, and
a bad --paint or --load-map is one line naming the option or file; a mouse
drag on the Axial map panel (--paint-drag) paints the texels along it.
Usage: viewer_xvfb_test.py XVFB_RUN NEBULA_VIEW NEBULA WORK
"""
import json
import os
import shutil
import subprocess
import sys

try:
    import numpy as np
    import matplotlib.image as mpimg
    import h5py
except ImportError as e:  # pragma: no cover
    print(f"SKIP: {e} (scripts/install-deps.sh installs python3-numpy, python3-matplotlib and python3-h5py)")
    sys.exit(77)

xvfb, view, nebula, work = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ, NEBULA_CACHE_DIR=os.path.join(work, "cache"))
# Under scripts/test-sanitize.sh: Mesa's driver is unloaded when the window closes, so
# LeakSanitizer sees its allocations in an "<unknown module>" it can neither name nor
# suppress. The viewer's own code (the session, without a window) is leak-checked by
# viewer_tests; the window's process is checked for everything but leaks.
view_env = dict(env, ASAN_OPTIONS=(env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":"))
with open(os.path.join(work, "s.toml"), "w") as f:
    f.write("""[density]
procedural = { n = 24, size_pc = 2.0 }
[[stars]]
luminosity_lsun = 2e5
class = "O5V"
[camera]
position = [1.0, -2.5, 1.0]
look_at = [1.0, 1.0, 1.0]
width = 96
height = 80
exposure = 0.05
""")


def run_view(*args, expect_ok=True, scene="s.toml"):
    cmd = [xvfb, "-a", "-s", "-screen 0 1024x768x24", view, scene, "--backend", "cpu",
           "--preview-photons", "16384", "--table-photons", "2000", *args]
    r = subprocess.run(cmd, cwd=work, env=view_env, capture_output=True, text=True, timeout=300)
    if expect_ok and r.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)}: exit {r.returncode}: {r.stdout} {r.stderr}")
    return r


def png(name):
    return mpimg.imread(os.path.join(work, name))[:, :, :3]


failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


run_view("--frames", "3", "--screenshot", "a.png", "--window-shot", "wa.png", "--save-scene", "a.toml")
run_view("--frames", "3", "--set", "dust.albedo=0.9", "--screenshot", "b.h5", "--window-shot", "wb.png",
         "--save-scene", "b.toml")
run_view("--frames", "2", "--set", "dust.albedo=0.9", "--screenshot", "b.png")

a, wa, wb, b = png("a.png"), png("wa.png"), png("wb.png"), png("b.png")
check(wa.shape == a.shape and np.array_equal(wa, a), "the window's pixels are the screenshot's (PNG, 1:1)")
check(np.array_equal(wb, b), "the edited scene's window pixels are its screenshot's")
check(a.mean() > 0.02, f"the window shows the nebula (mean level {a.mean():.3f})")
dust = a.sum(axis=2) > 0.05  # pixels with dust, below white
check(wb[dust].mean() > 1.15 * wa[dust].mean(),
      f"higher albedo brightens the dust in the window: mean {wa[dust].mean():.3f} -> {wb[dust].mean():.3f}")

# The saved scene renders the viewer's image again, bit for bit on the pixels with signal.
r = subprocess.run([nebula, "render", "b.toml", "-o", "rb.h5", "--backend", "cpu", "-q", "--table-photons", "2000"], cwd=work, env=env,
                   capture_output=True, text=True, timeout=300)
check(r.returncode == 0, f"nebula render of the saved scene ({r.stderr.strip()})")
r = subprocess.run([nebula, "compare", "rb.h5", "b.h5", "--json", "--signal", "1e-9"], cwd=work, env=env,
                   capture_output=True, text=True, timeout=60)
bands = json.loads(r.stdout)["bands"] if r.returncode == 0 else []
check(len(bands) == 3 and all(x["rel_l1"] == 0 and x["worst_1pct"] == 0 for x in bands),
      f"the saved scene re-renders to the viewer's image: {[(x['band'], x['rel_l1']) for x in bands]}")
r2 = subprocess.run([nebula, "render", "a.toml", "-o", "ra.h5", "--backend", "cpu", "-q", "--table-photons", "2000"], cwd=work, env=env,
                    capture_output=True, text=True, timeout=300)
r3 = subprocess.run([nebula, "compare", "b.h5", "ra.h5", "--json"], cwd=work, env=env, capture_output=True, text=True)
biases = [x["bias"] for x in json.loads(r3.stdout)["bands"]] if r3.returncode == 0 else []
check(len(biases) == 3 and all(x > 0.2 for x in biases), f"albedo 0.9 against 0.6 in the science pixels: bias {biases}")

# The fisheye: the dome circle, black corners.
run_view("--frames", "2", "--set", "camera.kind=fisheye", "--set", "camera.height=96", "--set", "camera.position=[1,0.3,1]",
         "--window-shot", "wf.png")
wf = png("wf.png")
check(wf.shape[:2] == (96, 96) and wf[0, 0].max() == 0 and wf[-1, -1].max() == 0 and wf[48, 48].max() > 0,
      "the fisheye shows its dome circle")

# A bad edit: one line naming the key, non-zero exit, no outputs.
r = run_view("--frames", "2", "--set", "dust.albedo=3", "--screenshot", "bad.png", expect_ok=False)
err = r.stderr.strip()
check(r.returncode != 0 and "dust.albedo" in err and "\n" not in err and not os.path.exists(os.path.join(work, "bad.png")),
      f"a bad --set is one line naming the key: {err!r}")

# ------------------------------------------------------------ painting an axial map
# The bipolar lobes (128 x 64 texels over z = -1 .. 1 pc, r = 0 .. 1 pc) lit
# by a star at their waist, seen from the side: up in the image is +z.
with open(os.path.join(work, "ax.toml"), "w") as f:
    f.write("""bands = ["B", "V", "R"]
[axial]
synthetic = "bipolar"
nx = 128
nr = 64
length_pc = 2.0
origin = [0.0, 0.0, -1.0]
emission_scale = 0.02
[[stars]]
position = [0.0, 0.0, 0.0]
luminosity_lsun = 2e4
class = "B0V"
[camera]
position = [6.0, 0.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_deg = 30
width = 96
height = 96
exposure = 1.0
""")


def run_ax(*args, expect_ok=True):
    return run_view("--frames", "2", *args, expect_ok=expect_ok, scene="ax.toml")


# A ring of dust (tau_v 0.3 per texel) around the axis at x = 40 texels (z = -0.375 pc),
# r = 16 texels (0.25 pc), radius 6 texels (0.094 pc): below the star, so below the image's middle.
ring = "40,16,6,0.3"
run_ax("--screenshot", "ax0.png")
run_ax("--paint", ring, "--screenshot", "ax1.png", "--window-shot", "wax1.png")
run_ax("--paint", ring, "--screenshot", "ax1.h5", "--save-scene", "ax1.toml", "--save-map", "ring.map.h5")
ax0, ax1, wax1 = png("ax0.png"), png("ax1.png"), png("wax1.png")
check(np.array_equal(wax1, ax1), "the painted scene's window pixels are its screenshot's")
gain = ax1.sum(axis=2) - ax0.sum(axis=2)
lower, upper = gain[48:].clip(min=0).sum(), gain[:48].clip(min=0).sum()
check(lower > 1.0 and lower > 5 * upper,
      f"painted dust brightens the nebula below the star, where it went: gain {lower:.2f} below, {upper:.2f} above")
# The ring's projection: |z + 0.375| <= 0.094 pc, 6 pc away, 30 degrees over 96 pixels; 0.06 pc
# more for its near side (5.75 pc away) and the pixels it touches.
per_pixel = 2 * 6.0 * np.tan(np.radians(15)) / 96
rows = [int(48 + (0.375 + dz) / per_pixel) for dz in (-0.154, 0.154)]
check(gain[rows[0]:rows[1] + 1].clip(min=0).sum() > 0.8 * gain.clip(min=0).sum(),
      f"the brightening lies in the ring's rows {rows} (z = -0.375 +- 0.094 pc)")
# Farther from the star than the ring, the lower lobe lies in its shadow; the upper lobe sees nothing of it.
check(gain[rows[1]:].clip(max=0).sum() < -1.0 and gain[:48].clip(max=0).sum() == 0,
      f"the ring shadows the lobe below it: {gain[rows[1]:].clip(max=0).sum():.2f} below, "
      f"{gain[:48].clip(max=0).sum():.2f} above the star")
r = subprocess.run([nebula, "render", "ax1.toml", "-o", "rax1.h5", "--backend", "cpu", "-q", "--table-photons", "2000"],
                   cwd=work, env=env, capture_output=True, text=True, timeout=300)
check(r.returncode == 0 and os.path.exists(os.path.join(work, "ax1.map.h5")),
      f"nebula render of the scene saved with its painted map ax1.map.h5 ({r.stderr.strip()})")
r = subprocess.run([nebula, "compare", "rax1.h5", "ax1.h5", "--json", "--signal", "1e-9"], cwd=work, env=env,
                   capture_output=True, text=True, timeout=60)
bands = json.loads(r.stdout)["bands"] if r.returncode == 0 else []
check(len(bands) == 3 and all(x["rel_l1"] == 0 and x["worst_1pct"] == 0 for x in bands),
      f"the painted scene saved re-renders to the viewer's image: {[(x['band'], x['rel_l1']) for x in bands]}")
run_ax("--load-map", "ring.map.h5", "--screenshot", "ax2.png")
check(np.array_equal(png("ax2.png"), ax1), "the saved map loads back to the painted picture")
run_ax("--paint", ring, "--brush-mode", "erase", "--brush-shape", "square", "--paint", "64,32,200,0",
       "--screenshot", "ax3.png")
check(ax0.max() > 0.1 and png("ax3.png").max() == 0, "erasing the whole map leaves a black frame")

# The interface's own painting: a mouse drag across the Axial map panel's image from
# (x, r) = (20, 40) to (100, 40) texels, radius 3, tau_v 0.4. Texels within 2 of the
# segment are painted; none beyond 3.5 (the mouse moves by whole pixels, 1/3 texel here).
run_view("--frames", "2", "--show-panels", "--window-width", "1000", "--window-height", "700",
         "--paint-drag", "20,40,100,40,3,0.4", "--save-map", "drag.h5", scene="ax.toml")
run_ax("--save-map", "nodrag.h5")
with h5py.File(os.path.join(work, "drag.h5"), "r") as f:
    dragged = f["tau_v"][:]
with h5py.File(os.path.join(work, "nodrag.h5"), "r") as f:
    plain = f["tau_v"][:]
x, r = np.meshgrid(np.arange(128) + 0.5, np.arange(64) + 0.5)  # texel centres, [nr][nx]
dist = np.hypot(x - np.clip(x, 20, 100), r - 40)
changed = dragged != plain
check(changed.any() and np.all(dragged[changed] == np.float32(0.4)) and dist[changed].max() <= 3.5 and
      np.all(dragged[dist <= 2] == np.float32(0.4)),
      f"a mouse drag on the panel paints along it: {changed.sum()} texels, the farthest "
      f"{dist[changed].max() if changed.any() else 0:.2f} from the segment")

# Bad paint and map input: one line naming the option or file, non-zero exit, nothing written.
with open(os.path.join(work, "junk.h5"), "w") as f:
    f.write("not HDF5")
for args, words in [(("--paint", "40,16,6"), ["--paint", "got 3 field"]),
                    (("--paint", "40,16,6,0.3,Ha"), ["--paint", "plane 'Ha'", "B, V, R"]),
                    (("--paint", "40,16,x,0.3"), ["--paint", "radius 'x'"]),
                    (("--load-map", "junk.h5"), ["junk.h5"]),
                    (("--brush-mode", "smear", "--paint", ring), ["--brush-mode"])]:
    r = run_ax(*args, "--screenshot", "badax.png", "--save-map", "badax.h5", expect_ok=False)
    err = r.stderr.strip()
    check(r.returncode != 0 and all(w in err for w in words) and "\n" not in err and
          not os.path.exists(os.path.join(work, "badax.png")) and not os.path.exists(os.path.join(work, "badax.h5")),
          f"{' '.join(args)}: one line naming it: {err!r}")
r = run_view("--frames", "2", "--paint", ring, "--screenshot", "badgrid.png", expect_ok=False)
err = r.stderr.strip()
check(r.returncode != 0 and "no [axial] map" in err and "\n" not in err and
      not os.path.exists(os.path.join(work, "badgrid.png")), f"--paint on a grid scene: {err!r}")

if failures:
    sys.exit("FAIL: " + "; ".join(failures))
print("viewer.xvfb: all checks passed")
