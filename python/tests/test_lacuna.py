"""The Python module against the engine and the CLI (registered in ctest as python.pytest).

LACUNA_CLI names build/lacuna (set by CMake); the CLI comparisons render the same settings
through `lacuna render` in a subprocess and compare the PNG's pixels byte for byte."""
import gc
import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import lacuna

CLI = os.environ.get("LACUNA_CLI", "")
SOURCE = os.environ.get("LACUNA_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CH2 = "/usr/share/mricron/templates/ch2.nii.gz"
DTYPES = [np.uint8, np.int16, np.uint16, np.float32]


def blobs(shape=(24, 28, 32), dtype=np.uint8, seed=1):
    """A (z, y, x) volume: two dense blobs in empty space (values 0..200), some noise."""
    z, y, x = np.indices(shape, dtype=np.float64)
    r1 = np.sqrt((x - 10) ** 2 + (y - 12) ** 2 + (z - 10) ** 2)
    r2 = np.sqrt((x - 22) ** 2 + (y - 16) ** 2 + (z - 14) ** 2)
    v = 200 * np.exp(-(r1 / 5) ** 2) + 150 * np.exp(-(r2 / 4) ** 2)
    v += np.random.default_rng(seed).uniform(0, 3, shape)
    return v.astype(dtype)


@pytest.fixture(scope="module")
def vol():
    return lacuna.Volume(blobs(), spacing=(1.0, 1.2, 0.8))


def cli(*args):
    if not CLI:
        pytest.skip("LACUNA_CLI not set (run through ctest)")
    r = subprocess.run([CLI, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


def write_raw(tmp_path, a, name="vol"):
    """a (z, y, x) as name_XxYxZ_type.raw, which the CLI and lacuna.load read with spacing 1."""
    z, y, x = a.shape
    path = tmp_path / f"{name}_{x}x{y}x{z}_{np.dtype(a.dtype).name}.raw"
    np.ascontiguousarray(a).astype(a.dtype.newbyteorder("<")).tofile(path)
    return str(path)


# ---- Volume from numpy ---------------------------------------------------------------------------
@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("order", ["C", "F"])
def test_every_dtype_and_order_reads_the_same_voxels(dtype, order):
    a = np.asarray(blobs(dtype=dtype), order=order)
    v = lacuna.Volume(a)
    assert v.shape == a.shape and v.dims == a.shape[::-1]
    assert v.dtype == np.dtype(dtype)
    assert np.array_equal(v.array, a)
    assert v.array.flags.c_contiguous and not v.array.flags.writeable
    # C order is adopted (no copy), Fortran order is copied once into C order.
    assert v.zero_copy == (order == "C")
    assert np.shares_memory(v.array, a) == (order == "C")
    assert v.range == pytest.approx((float(a.min()), float(a.max())))


@pytest.mark.parametrize("dtype", DTYPES)
def test_c_and_fortran_order_render_the_same_bytes(dtype):
    a = blobs(dtype=dtype)
    c = lacuna.Session(lacuna.Volume(a), "ct-bone").render(size=48).image
    f = lacuna.Session(lacuna.Volume(np.asfortranarray(a)), "ct-bone").render(size=48).image
    assert c.shape == (48, 48, 4) and c.dtype == np.uint8
    assert c[..., :3].any(), "the blobs must be visible"
    assert np.array_equal(c, f)


def test_nibabel_axes_take_a_fortran_array_without_a_copy():
    a = blobs()
    ijk = a.T  # (x, y, z), Fortran-contiguous: nibabel's layout
    v = lacuna.Volume(ijk, axes="xyz")
    assert v.zero_copy and v.shape == a.shape and np.array_equal(v.array, a)


def test_strided_arrays_are_copied_correctly():
    a = blobs(shape=(20, 30, 40))
    s = a[::2, 1:, ::-1]
    v = lacuna.Volume(s)
    assert not v.zero_copy and np.array_equal(v.array, s)
    be = blobs(dtype=np.uint16).astype(">u2")  # non-native byte order: converted
    assert np.array_equal(lacuna.Volume(be).array, be.astype(np.uint16))


def test_other_dtypes_are_converted_as_the_cli_readers_do():
    a = blobs(dtype=np.int16)
    assert lacuna.Volume(a.astype(np.int8)).dtype == np.int16
    v = lacuna.Volume(a.astype(np.float64))
    assert v.dtype == np.float32 and np.array_equal(v.array, a.astype(np.float32))
    for bad in (np.int64, np.bool_, np.complex64):
        with pytest.raises(ValueError, match=r"^array: dtype: expected uint8, int16"):
            lacuna.Volume(a.astype(bad))


@pytest.mark.parametrize("shape,message", [
    ((5, 5), r"^array: shape: expected 3 axes"),
    ((2, 3, 4, 5), r"^array: shape: expected 3 axes"),
    ((0, 5, 5), r"^array: shape: expected 2\.\.32768 voxels per axis"),
    ((5, 1, 5), r"^array: shape: expected 2\.\.32768 voxels per axis"),
])
def test_bad_shapes_raise_one_line(shape, message):
    with pytest.raises(ValueError, match=message):
        lacuna.Volume(np.zeros(shape, np.uint8))


def test_bad_values_and_geometry_raise_one_line():
    a = blobs(dtype=np.float32)
    a[3, 4, 5] = np.nan
    with pytest.raises(ValueError, match=r"^array: voxel \(5,4,3\).*NaN"):
        lacuna.Volume(a)
    good = blobs()
    for spacing in [(1, float("nan"), 1), (1, 0, 1), (-1, 1, 1)]:
        with pytest.raises(ValueError, match=r"^array: spacing"):
            lacuna.Volume(good, spacing=spacing)
    with pytest.raises(ValueError, match=r"^array: spacing: expected three numbers"):
        lacuna.Volume(good, spacing=(1, 1))
    with pytest.raises(ValueError, match=r"^array: affine: expected a 4x4"):
        lacuna.Volume(good, affine=np.eye(3))
    shear = np.eye(4)
    shear[0, 1] = 0.5
    with pytest.raises(ValueError, match=r"^array: direction"):
        lacuna.Volume(good, affine=shear)
    with pytest.raises(ValueError, match=r"^array: spacing: give spacing or affine"):
        lacuna.Volume(good, spacing=(1, 1, 1), affine=np.eye(4))


def test_the_affine_and_spacing_round_trip():
    a = blobs()
    v = lacuna.Volume(a, spacing=(0.5, 2, 3))
    assert v.spacing == (0.5, 2, 3)
    assert np.allclose(v.affine, np.diag([0.5, 2, 3, 1]))
    # LPS-ordered axes (a DICOM-like series), voxel sizes and an origin.
    aff = np.array([[-0.7, 0, 0, 90], [0, -0.9, 0, 120], [0, 0, 1.5, -60], [0, 0, 0, 1.0]])
    w = lacuna.Volume(a, affine=aff)
    assert np.allclose(w.affine, aff) and w.spacing == pytest.approx((0.7, 0.9, 1.5))
    assert w.orientation == "LPS"


def test_the_histogram_is_numpys():
    for dtype in (np.uint8, np.float32):
        a = blobs(dtype=dtype)
        v = lacuna.Volume(a)
        for bins in (256, 17):
            counts, edges = v.histogram(bins)
            ref_counts, ref_edges = np.histogram(a, bins, range=v.range)
            assert np.array_equal(counts, ref_counts) and np.allclose(edges, ref_edges)
            assert counts.sum() == a.size
    counts, _ = lacuna.Volume(blobs()).histogram(10, range=(50, 100))
    assert np.array_equal(counts, np.histogram(blobs(), 10, range=(50, 100))[0])


def test_a_volume_outlives_its_array_and_an_array_outlives_its_volume():
    a = blobs()
    expected = a.copy()
    before = sys.getrefcount(a)
    v = lacuna.Volume(a)
    assert v.zero_copy and sys.getrefcount(a) == before + 1  # the Volume holds the array
    del a
    gc.collect()
    assert np.array_equal(v.array, expected)
    img = lacuna.Session(v, "ct-bone").render(size=32).image
    s = lacuna.Session(lacuna.Volume(expected), "ct-bone")
    assert np.array_equal(img, s.render(size=32).image)
    view = v.array
    del v, s
    gc.collect()
    assert np.array_equal(view, expected)  # the view keeps the Volume (and its voxels) alive
    b = blobs()
    before = sys.getrefcount(b)
    w = lacuna.Volume(b)
    del w
    gc.collect()
    assert sys.getrefcount(b) == before  # released with the last Volume


def test_load_reads_what_the_cli_reads(tmp_path):
    a = blobs(dtype=np.int16)
    path = write_raw(tmp_path, a)
    v = lacuna.load(path)
    assert v.shape == a.shape and np.array_equal(v.array, a) and v.spacing == (1, 1, 1)
    nrrd = str(tmp_path / "vol.nrrd")
    cli("generate", "sphere", "--dims", "20x22x24", "--out", nrrd)
    g = lacuna.load(nrrd)
    assert g.dims == (20, 22, 24)
    # Every other format the CLI writes (and reads): the same voxels and the same world.
    for name in ("vol.nii.gz", "vol.nii", "vol.mha", "vol.mhd", "vol.nhdr", "dicom/"):
        other = str(tmp_path / name) + ("/" if name.endswith("/") else "")  # a DICOM folder
        cli("generate", "sphere", "--dims", "20x22x24", "--out", other)
        h = lacuna.load(other)
        assert h.dims == g.dims and np.array_equal(h.array, g.array), name
        assert np.allclose(h.affine, g.affine, atol=1e-4), name
    with pytest.raises(OSError, match=r"missing\.nii"):
        lacuna.load(str(tmp_path / "missing.nii"))
    with pytest.raises(ValueError, match=r"give both dims and dtype"):
        lacuna.load(str(tmp_path / "x.raw"), dims=(2, 2, 2))


def test_load_picks_a_volume_of_a_4d_nifti(tmp_path):
    nib = pytest.importorskip("nibabel")
    series = np.stack([blobs(dtype=np.uint8).T + 10 * t for t in range(3)], axis=-1)  # (x, y, z, t)
    path = str(tmp_path / "series.nii.gz")
    nib.save(nib.Nifti1Image(series, np.diag([0.5, 1.0, 2.0, 1.0])), path)
    for t in range(3):
        v = lacuna.load(path, frame=t)
        assert np.array_equal(v.array, series[..., t].T) and v.spacing == (0.5, 1.0, 2.0)
    with pytest.raises(OSError, match=r"frame: the file holds 3 volumes along dim\[4\]; choose one \(0\.\.2\)"):
        lacuna.load(path)
    with pytest.raises(OSError, match=r"frame: expected 0\.\.2, got 3"):
        lacuna.load(path, frame=3)


def test_a_nifti_pair_loads_as_its_nii(tmp_path):
    nib = pytest.importorskip("nibabel")
    a = blobs(dtype=np.int16).T  # (x, y, z)
    affine = np.array([[-0.5, 0, 0, 10], [0, 1.5, 0, -4], [0, 0, 2, 3], [0, 0, 0, 1]])
    nib.save(nib.Nifti1Pair(a, affine), str(tmp_path / "pair.hdr"))
    nib.save(nib.Nifti1Image(a, affine), str(tmp_path / "one.nii"))
    one = lacuna.load(str(tmp_path / "one.nii"))
    for name in ("pair.hdr", "pair.img"):
        v = lacuna.load(str(tmp_path / name))
        assert np.array_equal(v.array, one.array) and np.allclose(v.affine, one.affine), name
    nib.save(nib.AnalyzeImage(a, affine), str(tmp_path / "analyze.hdr"))
    with pytest.raises(OSError, match=r"analyze\.hdr: header: not a NIfTI-1 pair header"):
        lacuna.load(str(tmp_path / "analyze.hdr"))


# ---- Transfer functions --------------------------------------------------------------------------
def test_transfer_functions_from_presets_files_and_points(tmp_path):
    assert "mr-brain" in lacuna.presets()
    assert lacuna.TransferFunction("mr-brain").name == "mr-brain"
    points = {"color": [[0, 1, 0.5, 0.2], [1, 1, 1, 1]], "opacity": [[0, 0], [0.3, 0], [1, 0.8]]}
    a = lacuna.TransferFunction(points)
    b = lacuna.TransferFunction(color=[(0, 1, 0.5, 0.2), (1, 1, 1, 1)],
                                opacity=[(0, 0), (0.3, 0), (1, 0.8)])
    assert a.opacity == b.opacity and a.color == b.color
    path = tmp_path / "tf.json"
    path.write_text(json.dumps(points))
    assert lacuna.TransferFunction(str(path)).opacity == a.opacity
    assert lacuna.TransferFunction(path).color == a.color  # os.PathLike
    b.opacity = [(0, 0), (1, 0.5)]
    assert b.opacity == [(0, 0), (1, 0.5)]
    vp = os.path.join(SOURCE, "tests", "data", "lacuna-mr.vp")
    if os.path.exists(vp):
        assert len(lacuna.TransferFunction(vp).opacity) > 1
    with pytest.raises(ValueError, match=r"unknown preset 'nope'"):
        lacuna.TransferFunction("nope")
    with pytest.raises(ValueError, match=r"^TransferFunction: opacity\[1\]: expected \[x, a\] with a in \[0,1\]"):
        lacuna.TransferFunction(color=[(0, 1, 1, 1)], opacity=[(0, 0), (1, 1.5)])
    with pytest.raises(ValueError, match=r"^TransferFunction: opacity: missing"):
        lacuna.TransferFunction(color=[(0, 1, 1, 1)])
    with pytest.raises(ValueError, match=r"opacity\[1\]"):
        b.opacity = [(0.5, 0), (0.2, 1)]


# ---- Frames: byte-identical to the CLI -------------------------------------------------------
CLI_CASES = [
    ([], {}),
    (["--azimuth", "70", "--elevation", "-20", "--zoom", "1.3"],
     dict(azimuth=70, elevation=-20, zoom=1.3)),
    (["--view", "left", "--shading", "phong"], dict(view="left", shading="phong")),
    (["--shading", "pbr", "--light", "dir:1,0.5,1", "--clip", "1,0,0,12"],
     dict(shading="pbr", light={"direction": (1, 0.5, 1)}, clip=[(1, 0, 0, 12)])),
    (["--blend", "mip", "--accel", "bitfield", "--step", "0.7"],
     dict(blend="mip", structure="bitfield", step=0.7)),
    (["--renderer", "slice", "--accel", "boxes", "--ert", "1"],
     dict(renderer="slice", structure="boxes", ert=1)),
    (["--ortho", "--background", "0.2,0.3,0.4", "--interpolation", "nearest", "--accel", "none"],
     dict(ortho=True, background=(0.2, 0.3, 0.4), interpolation="nearest", structure="none")),
]


@pytest.mark.parametrize("flags,kwargs", CLI_CASES)
def test_a_frame_is_the_clis_frame_byte_for_byte(tmp_path, flags, kwargs):
    a = blobs()
    path = write_raw(tmp_path, a)
    out = str(tmp_path / "cli.png")
    cli("render", path, "--tf", "ct-bone", "--width", "64", "--height", "48", "--out", out, *flags)
    ref = lacuna.read_png(out)
    for v in (lacuna.load(path), lacuna.Volume(a), lacuna.Volume(np.asfortranarray(a))):
        img = lacuna.Session(v, "ct-bone").render(width=64, height=48, **kwargs).image
        assert img.shape == (48, 64, 4)
        assert np.array_equal(img, ref)
    assert ref[..., :3].any()


def test_a_real_file_and_its_nibabel_array_give_the_clis_frame(tmp_path):
    if not os.path.exists(CH2):
        pytest.skip("mricron-data not installed")
    nib = pytest.importorskip("nibabel")
    out = str(tmp_path / "ch2.png")
    cli("render", CH2, "--tf", "mr-skin", "--size", "64", "--view", "anterior", "--out", out)
    ref = lacuna.read_png(out)
    s = lacuna.Session(lacuna.load(CH2), "mr-skin")
    assert np.array_equal(s.render(size=64, view="anterior").image, ref)
    img = nib.load(CH2)
    v = lacuna.Volume(np.asanyarray(img.dataobj), affine=img.affine, axes="xyz")
    assert v.zero_copy or not np.asanyarray(img.dataobj).flags.f_contiguous
    assert np.allclose(v.affine, img.affine, atol=1e-4)
    assert np.array_equal(lacuna.Session(v, "mr-skin").render(size=64, view="anterior").image, ref)


def test_a_json_tf_and_two_tfs_match_the_cli(tmp_path):
    a = blobs()
    path = write_raw(tmp_path, a)
    tf = {"color": [[0, 1, 0.3, 0.1], [1, 1, 1, 0.8]], "opacity": [[0, 0], [0.2, 0], [1, 0.9]]}
    tf_path = tmp_path / "tf.json"
    tf_path.write_text(json.dumps(tf))
    out = str(tmp_path / "cli.png")
    cli("render", path, "--tf", str(tf_path), "--tf-back", "ct-bone", "--clip", "0,1,0,14",
        "--size", "40", "--out", out)
    s = lacuna.Session(a, tf, back_tf="ct-bone")
    assert np.array_equal(s.render(size=40, clip=(0, 1, 0, 14)).image, lacuna.read_png(out))
    with pytest.raises(ValueError, match=r"^back_transfer_function: two_tfs: expected a clip plane"):
        s.render(size=40)


def test_segments_match_the_cli(tmp_path):
    a = blobs()
    labels = np.zeros(a.shape, np.uint8)
    labels[:, :, :16] = 1
    labels[:, :, 16:] = 2
    path, lpath = write_raw(tmp_path, a), write_raw(tmp_path, labels, "labels")
    out = str(tmp_path / "cli.png")
    cli("render", path, "--tf", "ct-bone", "--labels", lpath, "--hide", "2", "--size", "40",
        "--out", out)
    s = lacuna.Session(a, "ct-bone", labels=labels)
    hidden = s.render(size=40, renderer="segments", hide=[2]).image
    assert np.array_equal(hidden, lacuna.read_png(out))
    assert not np.array_equal(hidden, s.render(size=40, renderer="segments").image)


# ---- Every structure gives the `none` image ----------------------------------------------------
def test_every_structure_gives_the_none_image(vol):
    s = lacuna.Session(vol, "ct-bone")
    march = [n for n in lacuna.structures() if n not in ("boxes", "label-octree")]
    for settings in (dict(), dict(shading="phong", clip=(0, 0, 1, 6))):
        none = s.render(size=48, structure="none", **settings).image
        assert none[..., :3].any()
        for name in march:
            assert np.array_equal(s.render(size=48, structure=name, **settings).image, none), name
    s.transfer_function = "ct-soft-tissue"  # a TF change: every structure brought up to it
    none = s.render(size=48, structure="none").image
    for name in march:
        assert np.array_equal(s.render(size=48, structure=name).image, none), name
    slice_none = s.render(size=48, renderer="slice", structure="none").image
    assert np.array_equal(s.render(size=48, renderer="slice", structure="boxes").image, slice_none)


def test_structures_are_built_once_and_reused(vol):
    s = lacuna.Session(vol, "ct-bone")
    first = s.render(size=32, structure="minmax")
    again = s.render(size=32, structure="minmax", azimuth=80)
    assert first.stats["build_seconds"] > 0 and again.stats["build_seconds"] == 0
    assert s.built_count == 1


# ---- Outputs -----------------------------------------------------------------------------------
def test_float32_stats_sample_counts_and_png(vol, tmp_path):
    s = lacuna.Session(vol, "ct-bone")
    f = s.render(size=40, sample_counts=True)
    g = s.render(size=40, dtype="float32")
    assert g.image.dtype == np.float32 and g.image.shape == (40, 40, 4)
    assert np.array_equal(g.image8, f.image)  # the 8-bit image comes along
    assert f.sample_counts.shape == (40, 40) and f.sample_counts.sum() == f.stats["samples"]
    assert f.stats["samples_per_ray"] > 0 and f.stats["seconds"] > 0
    image, stats = f
    assert image is f.image and stats is f.stats and np.asarray(f) is f.image
    f.save_png(tmp_path / "f.png")
    assert np.array_equal(lacuna.read_png(str(tmp_path / "f.png")), f.image)
    g.save_png(tmp_path / "g.png")
    assert np.array_equal(lacuna.read_png(str(tmp_path / "g.png")), f.image)
    png = f._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_orbit_gives_evenly_spaced_cameras(vol):
    cams = lacuna.orbit(4, elevation=10)
    assert [c["azimuth"] for c in cams] == [30, 120, 210, 300]
    s = lacuna.Session(vol, "ct-bone")
    frames = list(s.orbit(3, size=24))
    assert len(frames) == 3
    assert np.array_equal(frames[1].image, s.render(size=24, azimuth=150).image)
    with pytest.raises(ValueError, match="orbit: n"):
        lacuna.orbit(0)


def to_bytes(rgba, background=(0.0, 0.0, 0.0)):
    """The renderers' write-out (src/render/pixel_driver.cpp) in numpy: float32 rgb + (1 - a) *
    background, clamped to [0, 1], times 255, rounded half away from zero; alpha 255."""
    a = rgba[..., 3:4]
    w = np.float32(1) - a
    rgb = rgba[..., :3] + w * np.asarray(background, np.float32)
    x = (np.clip(rgb, np.float32(0), np.float32(1)) * np.float32(255)).astype(np.float64)
    out = np.full(rgba.shape, 255, np.uint8)
    out[..., :3] = np.floor(x + 0.5).astype(np.uint8)  # x in [0, 255]: exact in float64
    return out


@pytest.mark.parametrize("settings", [
    dict(),
    dict(background=(0.2, 0.3, 0.4), shading="phong", structure="bitfield"),
    dict(renderer="slice", structure="boxes", background=(0.5, 0.1, 0.9)),
])
def test_float32_is_the_renderers_rgba_before_rounding(vol, settings):
    s = lacuna.Session(vol, "ct-bone")
    f = s.render(size=40, **settings)
    g = s.render(size=40, dtype="float32", **settings)
    assert g.image.dtype == np.float32 and np.array_equal(g.image8, f.image)
    rgba = g.image
    # Premultiplied RGBA: opacity in [0, 1], unshaded colour <= opacity (a shaded one may
    # exceed it: specular light), partial opacities present (values an 8-bit image cannot
    # carry), and the 8-bit image follows from it exactly.
    assert rgba[..., 3].min() >= 0 and rgba[..., 3].max() <= 1.0 + 1e-6
    if "shading" not in settings:
        assert np.all(rgba[..., :3] <= rgba[..., 3:4] + 1e-5)
    alpha = rgba[..., 3]
    assert np.any((alpha > 0.05) & (alpha < 0.95))
    assert not np.array_equal(rgba, np.round(rgba * 255) / 255)
    assert np.array_equal(to_bytes(rgba, settings.get("background", (0, 0, 0))), f.image)


def test_float32_segments(tmp_path):
    a = blobs()
    labels = np.zeros(a.shape, np.uint8)
    labels[:, :, 16:] = 1
    s = lacuna.Session(a, "ct-bone", labels=labels)
    g = s.render(size=40, renderer="segments", dtype="float32", background=(0.1, 0.2, 0.3))
    assert np.array_equal(to_bytes(g.image, (0.1, 0.2, 0.3)), g.image8)
    assert g.image[..., 3].max() > 0


def test_up_rolls_the_camera_about_the_view_direction(vol):
    s = lacuna.Session(vol, "ct-bone")
    base = s.render(size=48, view="anterior")
    # Superior, the default, in any length: the same bytes.
    assert np.array_equal(s.render(size=48, view="anterior", up=(0, 0, 2.5)).image, base.image)
    # Inferior up turns the picture by 180 degrees; +x up (the anterior view's image left,
    # Camera::orbit's right being -x there) turns it by 90 degrees clockwise: the same rays up
    # to the float rounding of the pixel grid, so the same picture up to a few rounded bytes.
    flipped = s.render(size=48, view="anterior", up=(0, 0, -1)).image
    left_up = s.render(size=48, view="anterior", up=(1, 0, 0)).image
    for img, turned in ((flipped, np.rot90(base.image, 2)), (left_up, np.rot90(base.image, -1))):
        assert not np.array_equal(img, base.image)
        diff = np.abs(img.astype(int) - turned.astype(int))
        assert diff.mean() < 0.5 and np.mean(diff > 8) < 0.01, (diff.mean(), np.mean(diff > 8))
    # With an eye and a target as well; and the pan follows the rolled screen axes.
    t = (15.5, 16.2, 9.2)
    e = s.render(size=48, eye=(15.5, 16.2 + 100, 9.2), target=t, up=(0, 0, -1)).image
    e0 = s.render(size=48, eye=(15.5, 16.2 + 100, 9.2), target=t).image
    assert np.abs(e.astype(int) - np.rot90(e0, 2).astype(int)).mean() < 0.5
    p = s.render(size=48, view="anterior", up=(0, 0, -1), pan=(0.2, 0.1)).image
    p0 = s.render(size=48, view="anterior", pan=(-0.2, -0.1)).image
    assert np.abs(p.astype(int) - np.rot90(p0, 2).astype(int)).mean() < 0.5


@pytest.mark.parametrize("kwargs,message", [
    (dict(view="anterior", up=(0, 1, 0)),
     r"^up: camera\.orbit\.up: expected a direction not parallel to the view direction$"),
    (dict(eye=(15, 100, 9), target=(15, 16, 9), up=(0, -3, 0)), r"^up: camera\.orbit\.up: .* not parallel"),
    (dict(up=(0, float("nan"), 1)), r"^up: camera\.orbit\.up: expected a finite non-zero direction$"),
    (dict(up=(0, 0, 0)), r"^up: camera\.orbit\.up: expected a finite non-zero direction$"),
    (dict(up=(0, 1)), r"^up: direction: expected three numbers, got 2$"),
])
def test_a_bad_up_raises_one_line(vol, kwargs, message):
    with pytest.raises(ValueError, match=message):
        lacuna.Session(vol, "ct-bone").render(size=8, **kwargs)


def test_eye_and_target_place_the_orbit_camera(vol):
    s = lacuna.Session(vol, "ct-bone")
    # The anterior view's eye (+y of the target) at the distance the orbit would take.
    a = s.render(size=32, view="anterior", target=(15.5, 16.2, 9.2), zoom=1).image
    b = s.render(size=32, eye=(15.5, 16.2 + 100, 9.2), target=(15.5, 16.2, 9.2)).image
    assert a[..., :3].any() and b[..., :3].any()
    c = s.render(size=32, eye=(15.5 + 100, 16.2, 9.2), target=(15.5, 16.2, 9.2)).image
    assert not np.array_equal(b, c)


# ---- Skipped share ------------------------------------------------------------------------------
def test_the_skipped_share_is_measured_against_the_reference_lattice(vol):
    s = lacuna.Session(vol, "ct-bone")
    # none without early termination takes every lattice sample: nothing skipped.
    none = s.render(size=40, structure="none", ert=1).stats
    assert none["lattice_samples"] == none["samples"] > 0 and none["skipped_fraction"] == 0
    bit = s.render(size=40, structure="bitfield").stats
    assert bit["lattice_samples"] == none["lattice_samples"]
    assert bit["skipped_fraction"] == pytest.approx(1 - bit["samples"] / bit["lattice_samples"])
    assert 0.3 < bit["skipped_fraction"] < 1, bit["skipped_fraction"]
    assert "skipped_fraction" in bit and set(dict(bit)) >= {"seconds", "samples", "lattice_samples"}
    assert "skipped_fraction" in repr(s.render(size=8).stats)
    # The slicer's share is the Session's own: non-empty voxels that occlusion culling and
    # clipping skipped (none without occlusion).
    sl = s.render(size=40, renderer="slice", structure="boxes").stats
    assert sl["skipped_fraction"] == 0 and "lattice_samples" not in sl
    oc = s.render(size=40, renderer="slice", structure="boxes", occlusion=True).stats
    assert 0 <= oc["skipped_fraction"] < 1
    labels = np.zeros(vol.shape, np.uint8)
    labels[:, :, 16:] = 1
    labels = lacuna.Volume(labels, spacing=vol.spacing)  # the segments march the labels' lattice
    seg = lacuna.Session(vol, "ct-bone", labels=labels).render(size=40, renderer="segments").stats
    assert 0 < seg["skipped_fraction"] < 1 and seg["lattice_samples"] == none["lattice_samples"]


# ---- Label styles -------------------------------------------------------------------------------
def test_label_styles_match_the_cli(tmp_path):
    a = blobs()
    labels = np.zeros(a.shape, np.uint8)
    labels[:, :, :16] = 1
    labels[:, :, 16:] = 2
    path, lpath = write_raw(tmp_path, a), write_raw(tmp_path, labels, "labels")
    style = {"name": "two", "labels": [{"label": 1, "color": [1, 0.2, 0.1], "opacity": 0.5},
                                       {"label": 2, "name": "right", "color": [0.1, 0.3, 1]}]}
    jpath = tmp_path / "style.json"
    jpath.write_text(json.dumps(style))
    lut = np.zeros(768, np.uint8)
    lut[1], lut[256 + 2], lut[512 + 1] = 200, 180, 90  # label 1 red-blue, label 2 green
    lutpath = tmp_path / "labels.lut"
    lut.tofile(lutpath)
    s = lacuna.Session(a, "ct-bone", labels=labels)
    plain = s.render(size=40, renderer="segments", label_tint=0.8).image
    for spec in (str(jpath), lutpath):
        out = str(tmp_path / "cli.png")
        cli("render", path, "--tf", "ct-bone", "--labels", lpath, "--label-style", str(spec),
            "--label-tint", "0.8", "--hide", "2", "--size", "40", "--out", out)
        got = s.render(size=40, renderer="segments", label_tint=0.8, label_style=spec, hide=[2])
        assert np.array_equal(got.image, lacuna.read_png(out)), spec
        assert not np.array_equal(got.image, plain)
    # A dict in the JSON format is the file's table.
    from_dict = s.render(size=40, renderer="segments", label_tint=0.8, label_style=style).image
    from_file = s.render(size=40, renderer="segments", label_tint=0.8, label_style=jpath).image
    assert np.array_equal(from_dict, from_file)
    table = s.label_table(style)
    assert [t["label"] for t in table] == [0, 1, 2] and not table[0]["visible"]
    assert table[1]["color"] == pytest.approx((1, 0.2, 0.1)) and table[1]["opacity"] == 0.5
    assert table[2]["name"] == "right"
    lut_table = s.label_table(str(lutpath))
    assert lut_table[1]["color"] == pytest.approx((200 / 255, 0, 90 / 255))


@pytest.mark.parametrize("style,error,message", [
    ({"labels": [{"label": 1, "opacity": 2}]}, ValueError,
     r"^label_style: labels\[0\]\.opacity: "),
    ({"labels": [{"label": 1, "colour": [1, 1, 1]}]}, ValueError,
     r"^label_style: labels\[0\]\.colour: unknown key"),
    ({"label": []}, ValueError, r"^label_style: labels: expected an object"),
    ("/nonexistent/style.json", OSError, r"^/nonexistent/style\.json: file: does not exist$"),
    (3, ValueError, r"^label_style: type: expected a \.json or \.lut file"),
])
def test_bad_label_styles_raise_one_line(style, error, message):
    a = blobs()
    s = lacuna.Session(a, "ct-bone", labels=(a > 100).astype(np.uint8))
    with pytest.raises(error, match=message):
        s.render(size=8, renderer="segments", label_style=style)
    assert s.render(size=8, renderer="segments").image.shape == (8, 8, 4)


# ---- Errors ------------------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs,message", [
    (dict(step=0), r"^step: sampling\.step: expected 0 < step <= 64$"),
    (dict(size=0), r"^width: width: expected 1\.\.16384 pixels$"),
    (dict(structure="nope"), r"^structure: structure: unknown 'nope'"),
    (dict(renderer="slice", structure="bitfield"), r"^structure: structure: the slice renderer takes"),
    (dict(renderer="slice", shading="phong"), r"^shading: features\.shading: the slice renderer has no"),
    (dict(shading="toon"), r"^shading: name: unknown 'toon'; expected one of: none, phong, pbr$"),
    (dict(view="top"), r"^view: view: expected anterior, posterior"),
    (dict(view="left", azimuth=3), r"^view: view: sets the azimuth"),
    (dict(leaf=3, structure="minmax"), r"^leaf: structure\.octree\.leaf_cells"),
    (dict(clip=(0, 0, 0, 1)), r"^clip: features\.clip_planes: expected a finite non-zero normal"),
    (dict(shading="phong", phong=(1, 1, 1, -1)), r"^phong: features\.phong: expected finite"),
    (dict(ert=1.5), r"^ert: sampling\.early_termination"),
    (dict(colour=1), r"^render: colour: unknown keyword"),
    (dict(hide=[1]), r"^hide: renderer: only renderer='segments'"),
    (dict(dtype="int16"), r"^dtype: dtype: expected uint8 or float32"),
    (dict(step="x"), r"^step: type: expected float"),
])
def test_bad_settings_raise_one_line(vol, kwargs, message):
    s = lacuna.Session(vol, "ct-bone")
    with pytest.raises(ValueError, match=message):
        s.render(**kwargs)
    assert s.render(size=8).image.shape == (8, 8, 4)  # the session still renders


def test_a_session_without_a_tf_says_so(vol):
    with pytest.raises(ValueError, match="transfer function"):
        lacuna.Session(vol).render(size=8)


# ---- Threads -----------------------------------------------------------------------------------
def test_two_threads_render_through_two_sessions_at_once(vol):
    settings = [dict(size=64, azimuth=10), dict(size=64, azimuth=200, shading="phong")]
    expected = [lacuna.Session(vol, "ct-bone").render(**k).image for k in settings]
    results = [None, None]
    errors = []

    def work(i):
        try:
            s = lacuna.Session(vol, "ct-bone", threads=1)
            for _ in range(3):
                results[i] = s.render(**settings[i]).image
        except Exception as e:  # reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for r, e in zip(results, expected):
        assert np.array_equal(r, e)


def test_two_threads_may_share_one_session(vol):
    s = lacuna.Session(vol, "ct-bone", threads=1)
    expected = s.render(size=48).image
    out = []
    threads = [threading.Thread(target=lambda: out.append(s.render(size=48).image)) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(out) == 2 and all(np.array_equal(o, expected) for o in out)


def test_the_gil_is_released_while_rendering():
    big = lacuna.Volume(blobs(shape=(96, 96, 96)))
    s = lacuna.Session(big, "ct-bone", threads=1)
    done = []

    def frames():  # three long frames: every sample, no early termination
        for _ in range(3):
            done.append(s.render(size=320, step=0.05, ert=1, structure="none"))

    t = threading.Thread(target=frames)
    last = time.perf_counter()
    gaps = []
    t.start()
    while t.is_alive():
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
        time.sleep(0.001)
    t.join()
    seconds = min(f.stats["seconds"] for f in done)
    assert seconds > 0.05, "the frames must be long enough to measure"
    # Holding the GIL for a frame would stall this loop for the whole frame (a gap of at least
    # `seconds`); released, the loop runs through it (gaps of a few ms, more on a loaded
    # machine: hence the margin).
    assert len(gaps) > 3 and max(gaps) < 0.75 * seconds, (len(gaps), max(gaps), seconds)


# ---- Installing ----------------------------------------------------------------------------------
def test_cmake_install_puts_an_importable_package_under_the_prefix(tmp_path):
    build, cmake = os.environ.get("LACUNA_BUILD_DIR"), os.environ.get("LACUNA_CMAKE")
    if not build or not cmake:
        pytest.skip("LACUNA_BUILD_DIR not set (run through ctest)")
    prefix = tmp_path / "prefix"
    r = subprocess.run([cmake, "--install", build, "--prefix", str(prefix)], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    site = prefix / os.environ["LACUNA_PYTHON_INSTALL_DIR"]
    assert (site / "lacuna" / "__init__.py").exists()
    code = ("import lacuna, numpy as np; "
            "v = lacuna.Volume(np.arange(64, dtype=np.uint8).reshape(4, 4, 4)); "
            "print(lacuna.__file__); print(lacuna.Session(v, 'ct-bone').render(size=8).image.shape)")
    env = dict(os.environ, PYTHONPATH=str(site))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == [str(site / "lacuna" / "__init__.py"), "(8, 8, 4)"]
