"""A worked example of the Python module (docs/python.md): the surface
brightness profile of the Fig. 12 scene, and an albedo x g grid of its total
V-band brightness, both in one session that keeps its grid and star bake.

    PYTHONPATH=build/python build/pyenv/bin/python docs/examples/python_study.py \
        --backend cuda --out docs/images/python_study.png
"""
import argparse
import time

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import nebula

parser = argparse.ArgumentParser()
parser.add_argument("--scene", default="scenes/fig12_reference.toml")
parser.add_argument("--backend", default="auto")
parser.add_argument("--size", type=int, default=256, help="image width and height")
parser.add_argument("--out", default="python_study.png")
args = parser.parse_args()

session = nebula.Session(args.scene, set={"camera.width": args.size, "camera.height": args.size},
                         backend=args.backend)

# 1. A radial profile about the star, from the image and its WCS alone.
image = session.render()
m = image.metadata
v = image.band("V")
# The star's pixel: where it projects (the scene's star sits at the look-at point here).
cy, cx = (np.array(v.shape) - 1) / 2.0
y, x = np.indices(v.shape)
r_deg = np.hypot((x - cx) * m["CDELT1"], (y - cy) * m["CDELT2"])
edges = np.linspace(0, r_deg.max(), 40)
which = np.digitize(r_deg.ravel(), edges)
profile = np.array([v.ravel()[which == k].mean() if np.any(which == k) else np.nan for k in range(1, len(edges))])

# 2. Total V-band radiance over an albedo x g grid: one sweep, the bake reused.
albedos = np.linspace(0.3, 0.9, 7)
gs = [0.0, 0.3, 0.6, 0.9]
start = time.time()
cube = session.sweep({"dust.albedo": albedos, "dust.g": gs})
seconds = time.time() - start
v_index = cube["bands"].index("V")
total = cube["data"][:, :, v_index].sum(axis=(-1, -2))  # (albedo, g)
reused = sum(r["bake_reused"] for r in cube["reports"])

fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
centres = 0.5 * (edges[1:] + edges[:-1])
a.semilogy(centres, profile, "k-")
a.set_xlabel("angle from the star (degrees)")
a.set_ylabel(f"mean V radiance ({m['units']})")
a.set_title("radial profile, a = 0.6, g = 0.6")
for j, g in enumerate(gs):
    b.plot(albedos, total[:, j] / total[0, 2], "o-", label=f"g = {g}")
b.set_xlabel("albedo")
b.set_ylabel("total V radiance / (a = 0.3, g = 0.6)")
b.set_title(f"albedo x g: {len(albedos) * len(gs)} renders in {seconds:.1f} s ({args.backend})")
b.legend()
fig.tight_layout()
fig.savefig(args.out, dpi=110)
print(f"{args.out}: {len(albedos) * len(gs)} points in {seconds:.1f} s, star bake reused {reused} times")
