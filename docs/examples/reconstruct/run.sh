#!/usr/bin/env bash
# Makes docs/images/axial_reconstruction.png: the map rendered, reconstructed
# (NNLS), then with 3% noise reconstructed without and with the smoothing the
# discrepancy principle chooses. Each row: the straightened input | the map
# (its own scale) | the map re-rendered. Run from the repository root after a build.
set -euo pipefail
root=$PWD
work=$(mktemp -d)
cp docs/examples/reconstruct/make_map.py docs/examples/reconstruct/demo.toml "$work"
cd "$work"
/usr/bin/python3 make_map.py
"$root"/build/bin/nebula render demo.toml -o demo.h5
/usr/bin/python3 - <<'PY'
import h5py, numpy as np, shutil
shutil.copy("demo.h5", "noisy.h5")
with h5py.File("noisy.h5", "r+") as f:
    d = f["image"][...]
    d += (0.03 * d.max() * np.random.default_rng(1).standard_normal(d.shape)).astype("f4")
    f["image"][...] = d
PY
nebula=("$root"/build/bin/nebula reconstruct --axis 256,96,180)
"${nebula[@]}" demo.h5 -o a.h5 --compare a.png
"${nebula[@]}" noisy.h5 -o b.h5 --compare b.png
"${nebula[@]}" noisy.h5 -o c.h5 --smoothness auto --compare c.png
/usr/bin/python3 - "$root"/docs/images/axial_reconstruction.png <<'PY'
import sys
from PIL import Image
rows = [Image.open(f).convert("RGB") for f in ["a.png", "b.png", "c.png"]]
out = Image.new("RGB", (rows[0].width, sum(r.height for r in rows) + 8), (255, 255, 255))
y = 0
for r in rows:
    out.paste(r, (0, y))
    y += r.height + 4
out.save(sys.argv[1], optimize=True)
PY
for m in a b c; do
  /usr/bin/python3 -c "
import h5py, numpy as np
t, g = h5py.File('demo_map.h5'), h5py.File('$m.h5')
d = sum(((g['emission_'+b][...].astype(float) - t['emission_'+b][...]) ** 2).sum() for b in 'BVR')
s = sum((t['emission_'+b][...].astype(float) ** 2).sum() for b in 'BVR')
print('$m: map error %.3g' % np.sqrt(d / s))"
done
