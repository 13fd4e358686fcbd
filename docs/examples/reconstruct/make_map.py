# The map behind docs/images/axial_reconstruction.png: two emitting lobes with a
# texture, a red ring at the waist and a core, 256 x 96 texels (docs/axial.md,
# "Reconstruction"). Run by docs/examples/reconstruct/run.sh.
import h5py, numpy as np
nx, nr = 256, 96
x = np.arange(nx)[None, :] + 0.5
r = np.arange(nr)[:, None] + 0.5
def shell(cx, ax, ar, w):
    d = np.sqrt(((x - cx) / ax) ** 2 + (r / ar) ** 2)
    return np.exp(-0.5 * ((d - 1.0) * ax / w) ** 2)
lobes = shell(78, 58, 42, 3.0) + shell(178, 58, 42, 3.0)
ring = np.exp(-0.5 * (((x - 128) / 5.0) ** 2 + ((r - 34) / 4.0) ** 2))
core = np.exp(-0.5 * (((x - 128) / 10.0) ** 2 + (r / 10.0) ** 2))
texture = 1.0 + 0.35 * np.sin(x / 4.0 + r / 9.0) * np.cos(r / 5.0)
e = {"B": 0.020 * lobes * texture + 0.004 * core, "V": 0.012 * lobes * texture + 0.02 * ring + 0.006 * core,
     "R": 0.008 * lobes * texture + 0.05 * ring + 0.006 * core}
with h5py.File("demo_map.h5", "w") as f:
    f["tau_v"] = np.zeros((nr, nx), dtype="f4")
    for b, v in e.items():
        f["emission_" + b] = v.astype("f4")
