"""Tests of the Python module against the pipeline and the command line."""
import os
import subprocess

import numpy as np
import pytest

import nebula

SCENE = """
[density]
procedural = { n = 16, size_pc = 2.0, seed = 3 }
[dust]
albedo = 0.6
g = 0.6
[[stars]]
luminosity_lsun = 2e5
class = "O5V"
[camera]
position = [1.0, -2.5, 1.0]
look_at = [1.0, 1.0, 1.0]
width = 24
height = 20
[render]
diffuse_photons = 65536
"""


@pytest.fixture(autouse=True)
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NEBULA_CACHE_DIR", str(tmp_path / "cache"))


def session(**kw):
    return nebula.Session.from_text(SCENE, backend="cpu", table_photons=1000, **kw)


def test_render_gives_radiance_planes_with_typed_metadata():
    img = session().render()
    assert img.data.shape == (3, 20, 24)
    assert img.bands == ["B", "V", "R"]
    assert np.isfinite(img.data).all() and (img.data >= 0).all() and img.data.sum() > 0
    m = img.metadata
    assert m["units"] == "solLum pc-2 sr-1"
    assert isinstance(m["albedo_V"], float) and m["albedo_V"] == 0.6
    assert m["stars"] == 1
    assert np.array_equal(img.band("V"), img.data[1])


def test_higher_albedo_brightens_the_dust():
    s = session()
    low = s.render({"dust.albedo": 0.3}).data.sum()
    high = s.render({"dust.albedo": 0.9}).data.sum()
    assert high > 1.5 * low


def test_an_edit_reuses_what_it_does_not_touch_and_changes_nothing_else():
    s = session()
    s.render()
    edited = s.render({"dust.albedo": 0.8})
    assert edited.report["bake_reused"] and not edited.report["diffuse_reused"]
    moved = s.render({"dust.albedo": 0.8, "camera.position": [1.2, -2.4, 1.1]})
    assert moved.report["bake_reused"] and moved.report["diffuse_reused"]
    # The same images as fresh sessions: reuse is invisible in the pixels.
    assert np.array_equal(edited.data, session().render({"dust.albedo": 0.8}).data)
    assert np.array_equal(moved.data, session(set={"camera.position": [1.2, -2.4, 1.1]}).render({"dust.albedo": 0.8}).data)


def test_the_module_and_the_command_line_render_the_same_image(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    out = tmp_path / "cli.fits"
    subprocess.run([os.environ["NEBULA_BIN"], "render", str(scene), "-o", str(out), "--backend", "cpu",
                    "--table-photons", "1000", "-q"], check=True, capture_output=True)
    cli = nebula.read_image(str(out))
    py = nebula.Session(str(scene), backend="cpu", table_photons=1000).render()
    assert np.array_equal(cli.data, py.data)
    py.write(str(tmp_path / "py.fits"))
    assert np.array_equal(nebula.read_image(str(tmp_path / "py.fits")).data, py.data)


def test_sweep_is_each_points_render():
    s = session()
    cube = s.sweep({"dust.albedo": [0.3, 0.9], "dust.g": [0.0, 0.6]})
    assert cube["data"].shape == (2, 2, 3, 20, 24)
    assert [k for k, _ in cube["axes"]] == ["dust.albedo", "dust.g"]
    # The albedos of one g share their photons, traced at the largest albedo:
    # its planes are the separate renders bit for bit, the others an
    # estimate of their own field (diffuse/diffuse_bake_test.cpp checks those).
    assert all(r["diffuse_shared_with"] == 1 for r in cube["reports"])
    for j, g in enumerate([0.0, 0.6]):
        ref = session().render({"dust.albedo": 0.9, "dust.g": g})
        assert np.array_equal(cube["data"][1, j], ref.data)
        low = session().render({"dust.albedo": 0.3, "dust.g": g})
        assert not np.array_equal(cube["data"][0, j], low.data)
    assert sum(r["bake_reused"] for r in cube["reports"]) == 3
    # Photons of its own for every point: every plane a separate render.
    separate = session().sweep({"dust.albedo": [0.3, 0.9], "dust.g": [0.6]}, share_photons=False)
    assert all(r["diffuse_shared_with"] == 0 for r in separate["reports"])
    for i, a in enumerate([0.3, 0.9]):
        assert np.array_equal(separate["data"][i, 0], session().render({"dust.albedo": a, "dust.g": 0.6}).data)


def test_truth_and_compare():
    s = session()
    mean, var = s.truth(spp=8)
    assert mean.data.shape == var.data.shape == (3, 20, 24)
    assert (var.data >= 0).all() and mean.data.sum() > 0
    same = nebula.compare(mean, mean, var)
    assert [b["band"] for b in same] == ["B", "V", "R"]
    assert all(b["bias"] == 0 and b["rel_l2_excess"] == 0 for b in same)
    scaled = nebula.Image(mean.data * 1.1, mean.bands)
    for b in nebula.compare(scaled, mean):
        assert b["bias"] == pytest.approx(0.1, rel=1e-5)


def test_tabulate_conserves_the_light_of_a_black_voxel_and_an_empty_one():
    t = nebula.tabulate(albedo=0.0, g=0.6, photons_per_row=2000, tau_bins=4, mu_bins=8, backend="cpu")
    assert t["P"].shape == (4, 8) and t["mu"].shape == (8,)
    assert (t["P"] == 0).all() and (t["total"] == 0).all()
    assert t["unscattered"][0] == pytest.approx(1.0)
    t = nebula.tabulate(albedo=1.0, g=0.6, photons_per_row=2000, tau_bins=4, mu_bins=8, backend="cpu")
    # With albedo 1 every photon leaves: scattered plus unscattered is all.
    assert np.allclose(t["total"] + t["unscattered"], 1.0, atol=1e-9)


def test_bad_input_names_the_key():
    s = session()
    with pytest.raises(nebula.Error, match="dust.albdo"):
        s.render({"dust.albdo": 0.5})
    with pytest.raises(nebula.Error, match="dust.albedo"):
        s.render({"dust.albedo": 1.5})
    with pytest.raises(TypeError, match="dust.g"):
        s.render({"dust.g": object()})
    with pytest.raises(ValueError, match="backend"):
        nebula.Session.from_text(SCENE, backend="gpu")
    with pytest.raises(nebula.Error, match="grid"):
        s.sweep({"dust.albedo": []})
    with pytest.raises(TypeError, match="dust.g"):
        s.sweep({"dust.g": ["a"]})
    assert issubclass(nebula.Error, ValueError)
