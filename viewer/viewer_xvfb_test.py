#!/usr/bin/env python3
"""nebula-view's real window under Xvfb with Mesa (ctest viewer.xvfb).

It starts and renders; the window's own pixels equal the screenshot PNG; a
scripted edit (albedo 0.6 -> 0.9) brightens the dust in the window's pixels and
in the science screenshot; the saved scene re-renders with `nebula render` to
the same image; the fisheye shows its dome circle; a bad --set is one line.
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
except ImportError as e:  # pragma: no cover
    print(f"SKIP: {e} (scripts/install-deps.sh installs python3-numpy and python3-matplotlib)")
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


def run_view(*args, expect_ok=True):
    cmd = [xvfb, "-a", "-s", "-screen 0 1024x768x24", view, "s.toml", "--backend", "cpu",
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

if failures:
    sys.exit("FAIL: " + "; ".join(failures))
print("viewer.xvfb: all checks passed")
