#!/usr/bin/env python3
"""validation.gallery_reuse: gallery.py's --render-only writes each HDF5 with its arguments beside it,
--reuse composes the montage from them without rendering again, and renders again what was rendered with
other arguments. Usage: gallery_test.py NEBULA ROOT WORK"""
import os
import shutil
import subprocess
import sys


def gallery(root, work, nebula, renders, *extra):
    command = [sys.executable, os.path.join(root, "validation", "gallery.py"), "--study", "axial_ms",
               "--nebula", nebula, "--backend", "cpu", "--no-truth", "--renders", renders, "--out", work] + list(extra)
    result = subprocess.run(command, capture_output=True, text=True, cwd=root)
    if result.returncode != 0:
        raise SystemExit(f"gallery.py {' '.join(extra)} failed: {result.stderr.strip()}")
    return result.stdout


def main():
    nebula, root, work = sys.argv[1:4]
    try:
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as e:
        print(f"skip: {e}")
        return 77
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    renders = os.path.join(work, "renders")
    out = gallery(root, work, nebula, renders, "--size", "16", "--render-only")
    names = sorted(f for f in os.listdir(renders) if f.endswith(".h5"))
    assert names == ["axial_ms_diffuse.h5", "axial_ms_none.h5"], names
    assert all(os.path.isfile(os.path.join(renders, n + ".args")) for n in names)
    assert not os.path.exists(os.path.join(work, "axial_diffuse.png")), "--render-only made a montage"
    assert "compose with --reuse" in out, out
    # Moved elsewhere (as from a GPU machine), the renders are still found: the record holds no folder.
    moved = os.path.join(work, "moved")
    shutil.move(renders, moved)
    renders = moved
    stamps = {n: os.path.getmtime(os.path.join(renders, n)) for n in names}
    out = gallery(root, work, nebula, renders, "--size", "16", "--reuse")
    assert out.count("reusing") == 2 and "$ " not in out, out
    assert os.path.isfile(os.path.join(work, "axial_diffuse.png"))
    assert stamps == {n: os.path.getmtime(os.path.join(renders, n)) for n in names}, "a reused file was rewritten"
    # Other arguments: rendered again, not reused.
    out = gallery(root, work, nebula, renders, "--size", "20", "--reuse")
    assert out.count("reusing") == 0 and out.count("$ ") == 2, out
    print("gallery.py: --render-only then --reuse composed without rendering; other arguments rendered again")
    return 0


if __name__ == "__main__":
    sys.exit(main())
