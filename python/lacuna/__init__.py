"""lacuna: CPU direct volume rendering with exact empty-space skipping (docs/python.md).

    import lacuna
    vol = lacuna.load("/usr/share/mricron/templates/ch2better.nii.gz")   # or lacuna.Volume(array)
    session = lacuna.Session(vol, "mr-brain")
    frame = session.render(size=512, view="anterior", shading="phong")
    frame.image          # H x W x 4 uint8 numpy array, the CLI's bytes for the same settings
    frame.stats          # seconds, samples_per_ray, build_seconds, ...
    frame.save_png("brain.png")

The extension (_lacuna) does the work; this file adds the Python-side conveniences: Session,
Frame, orbit().
"""
import collections.abc as _abc
import os as _os
import tempfile as _tempfile

from ._lacuna import (TransferFunction, Volume, _Session, load, presets, read_png, save_png,
                      structures)

__all__ = ["Volume", "TransferFunction", "Session", "Renderer", "Frame", "Stats", "load", "presets",
           "structures", "orbit", "render", "save_png", "read_png"]


class Stats(_abc.Mapping):
    """A frame's counters (a read-only mapping, printed as a dict). 'lattice_samples' and the
    ray marcher's and segment renderer's 'skipped_fraction' (1 - samples / lattice_samples, the
    viewer's "space skipped") cost a ray set-up per pixel: they are computed when first read, so
    render() itself does not pay for them."""

    __slots__ = ("_d", "_lattice")

    def __init__(self, d, lattice=None):
        self._d = d
        self._lattice = lattice

    def _fill(self):
        if self._lattice is not None:
            n = self._lattice()
            self._lattice = None
            self._d["lattice_samples"] = n
            s = self._d["samples"]
            self._d["skipped_fraction"] = 1.0 - s / n if n and s < n else 0.0

    def __getitem__(self, key):
        if key not in self._d and key in ("lattice_samples", "skipped_fraction"):
            self._fill()
        return self._d[key]

    def __iter__(self):
        self._fill()
        return iter(self._d)

    def __len__(self):
        self._fill()
        return len(self._d)

    def __repr__(self):
        return repr(dict(self))


class Frame:
    """One rendered frame: .image (H x W x 4: uint8, or with dtype='float32' the renderer's
    premultiplied RGBA before the background and the 8-bit rounding), .image8 (the 8-bit image,
    the CLI's bytes, whatever the dtype), .stats (a Stats mapping), .sample_counts (H x W uint32
    with sample_counts=True, else None).

    np.asarray(frame) is the image; `image, stats = frame` unpacks; a notebook shows it."""

    __slots__ = ("image", "image8", "stats", "sample_counts")

    def __init__(self, image, stats, sample_counts=None, image8=None):
        self.image = image
        self.image8 = image if image8 is None else image8
        self.stats = stats
        self.sample_counts = sample_counts

    def __array__(self, dtype=None, copy=None):
        return self.image if dtype is None else self.image.astype(dtype)

    def __iter__(self):
        yield self.image
        yield self.stats

    @property
    def shape(self):
        return self.image.shape

    def save_png(self, path):
        """Writes the image as a PNG (the CLI's writer: the same file for the same pixels)."""
        save_png(_os.fspath(path), self.image8)

    def _repr_png_(self):
        with _tempfile.TemporaryDirectory() as d:
            path = _os.path.join(d, "frame.png")
            save_png(path, self.image8)
            with open(path, "rb") as f:
                return f.read()

    def __repr__(self):
        h, w = self.image.shape[:2]
        return "<lacuna.Frame %dx%d %s, %.1f ms, %.1f samples/ray>" % (
            w, h, self.image.dtype, self.stats["seconds"] * 1e3, self.stats["samples_per_ray"])


def _as_volume(v):
    if isinstance(v, Volume):
        return v
    if isinstance(v, (str, _os.PathLike)):
        return load(_os.fspath(v))
    return Volume(v)


class Session:
    """A volume, its transfer functions and the skipping structures built for them, kept across
    frames (lacuna::Session). render(**settings) returns a Frame.

    Session(volume, tf=None, *, back_tf=None, labels=None, threads=0)
      volume: a Volume, a numpy array (Volume(array)) or a file (lacuna.load(path)).
      tf, back_tf: anything TransferFunction() takes; back_tf is used behind clip plane 0.
      labels: a label volume of the same dims, for renderer='segments' (mask mode).
      threads: render and build threads (0: all cores).

    The GIL is released while a frame builds and renders; one frame at a time per session
    (another thread's render() waits), any number of sessions at once."""

    def __init__(self, volume, tf=None, *, back_tf=None, labels=None, threads=0):
        self._volume = _as_volume(volume)
        self._s = _Session(self._volume, threads)
        if tf is not None:
            self.transfer_function = tf
        if back_tf is not None:
            self.back_transfer_function = back_tf
        if labels is not None:
            self._s.set_labels(_as_volume(labels))

    @property
    def volume(self):
        return self._volume

    @property
    def transfer_function(self):
        return self._s.transfer_function()

    @transfer_function.setter
    def transfer_function(self, tf):
        self._s.set_transfer_function(tf)

    @property
    def back_transfer_function(self):
        return self._back

    @back_transfer_function.setter
    def back_transfer_function(self, tf):
        self._s.set_back_transfer_function(tf)
        self._back = None if tf is None else TransferFunction(tf) if not isinstance(
            tf, TransferFunction) else tf

    _back = None

    def set_labels(self, labels):
        self._s.set_labels(_as_volume(labels))

    def label_table(self, label_style=None):
        """The label table a segments frame starts from: one dict per label value (label, name,
        color, opacity, visible), the session's default or label_style (a .json/.lut file or a
        dict in the JSON format of docs/segments.md) over it."""
        return self._s.label_table(label_style)

    def render(self, **settings):
        """Renders one frame; the keywords are `lacuna render`'s flags (docs/python.md):
        size/width/height, renderer ('march', 'slice', 'segments'), structure ('auto', ...),
        view or azimuth/elevation (or eye/target), up, zoom, fov, ortho, pan, step, ert,
        interpolation, background, shading, phong, pbr, gradient_volume, gradient_opacity,
        light, light_intensity, shadows, shadow_step, light_volume, clip, crop, blend, jitter,
        occlusion, segments, label_tint, label_style, show, hide, leaf, bits, sample_counts, dtype, refine."""
        image, image8, stats, counts, lattice = self._s.render(**settings)
        return Frame(image, Stats(stats, lattice), counts, image8)

    def orbit(self, n, **settings):
        """Yields n frames around the volume (lacuna.orbit(n)), the other settings fixed."""
        for camera in orbit(n, elevation=settings.pop("elevation", 15.0),
                            start=settings.pop("azimuth", 30.0)):
            yield self.render(**camera, **settings)

    @property
    def built_count(self):
        return self._s.built_count()

    def drop_structures(self):
        self._s.drop_structures()


Renderer = Session


def orbit(n, elevation=15.0, start=30.0):
    """n cameras evenly around the superior axis, for a movie: a list of dicts to pass to
    render(**camera). Azimuths start + 360 * i / n degrees."""
    if int(n) != n or n < 1:
        raise ValueError("orbit: n: expected a positive whole number of frames, got %r" % (n,))
    return [{"azimuth": start + 360.0 * i / n, "elevation": elevation} for i in range(int(n))]


def render(volume, tf, **settings):
    """One frame without keeping a session: Session(volume, tf).render(**settings)."""
    return Session(volume, tf).render(**settings)
