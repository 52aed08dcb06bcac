// The `lacuna` Python module (docs/python.md): numpy arrays in, images out, through the same
// lacuna::Session and FrameSpec as the CLI and the viewer (STYLE.md habit 11). This file is the
// Python edge: Python values become typed FrameSpec fields here, and library errors become
// ValueError / OSError with the library's one-line message (a FrameSpec field is renamed to the
// render() keyword that sets it, as the CLI renames it to its flag).
//
// Memory: a Volume made from a C-contiguous uint8/int16/uint16/float32 array of shape (z, y, x)
// adopts the array's buffer (no copy; the Volume holds a reference to the array). Any other
// layout or voxel type is copied once into such an array, which the Volume then owns.
//
// Threads: the GIL is released while a Session builds or renders; one mutex per Session keeps
// its frames one at a time (lacuna::Session is not thread-safe), so two Python threads may
// render through two sessions at once, or queue on one.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/image.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"
#include "lacuna/segments.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"
#include "lacuna/views.h"
#include "lacuna/volume.h"
#include "render/sample_analysis.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace {

using lacuna::Error;

[[noreturn]] void raise(PyObject* type, const std::string& message) {
    PyErr_SetString(type, message.c_str());
    throw py::error_already_set();
}
[[noreturn]] void value_error(const std::string& where, const std::string& field,
                              const std::string& what) {
    raise(PyExc_ValueError, where + ": " + field + ": " + what);
}

// ---- FrameSpec fields -> render() keywords (the CLI's frame_flags.cpp, for Python) ------------
constexpr std::pair<const char*, const char*> kKeywords[] = {
    {"width", "width"},
    {"height", "height"},
    {"camera.orbit.zoom", "zoom"},
    {"camera.orbit.fov_y_deg", "fov"},
    {"camera.orbit.up", "up"},
    {"camera.orbit", "azimuth/elevation"},
    {"camera.pan", "pan"},
    {"background", "background"},
    {"sampling.step", "step"},
    {"sampling.early_termination", "ert"},
    {"sampling.interpolation", "interpolation"},
    {"structure.octree.leaf_cells", "leaf"},
    {"structure.leaf_cells", "leaf"},
    {"structure.bits", "bits"},
    {"structure.coalesce_edge", "coalesce_edge"},
    {"structure.coalesce", "coalesce"},
    {"structure", "structure"},
    {"features.shading", "shading"},
    {"features.phong", "phong"},
    {"features.pbr", "pbr"},
    {"features.gradient_opacity", "gradient_opacity"},
    {"features.light.intensity", "light_intensity"},
    {"features.light", "light"},
    {"features.shadows.step", "shadow_step"},
    {"features.shadows.light_volume_stride", "light_volume_stride"},
    {"features.shadows", "shadows"},
    {"features.clip_planes", "clip"},
    {"features.crop_box", "crop"},
    {"features.crop", "crop"},
    {"features.blend", "blend"},
    {"features.jitter", "jitter"},
    {"features", "shading/light/clip"},
    {"two_tfs", "back_transfer_function"},
    {"count_samples", "sample_counts"},
    {"slicer.occlusion_threshold", "occlusion_threshold"},
    {"slicer.occlusion_map", "occlusion_map"},
    {"slicer.occlusion", "occlusion"},
    {"segments.tint", "label_tint"},
    {"segments", "segments"},
};

std::string keyword_of_field(const std::string& field) {
    size_t best = 0;
    std::string keyword = "render";
    for (const auto& [prefix, k] : kKeywords) {
        const std::string p = prefix;
        const bool match = field.compare(0, p.size(), p) == 0 &&
                           (field.size() == p.size() || field[p.size()] == '.');
        if (match && p.size() > best) best = p.size(), keyword = k;
    }
    return keyword;
}

// A FrameError as the Python user's line: "<keyword>: <field>: <expected>".
std::string python_message(const lacuna::FrameError& e) {
    return keyword_of_field(e.field()) + ": " + e.field() + ": " + e.expected();
}

// ---- Volume -------------------------------------------------------------------------------------
// A reference to a Python object as the shared owner of a Volume's voxels: released under the
// GIL (the last Volume copy may die in a thread that does not hold it).
std::shared_ptr<void> hold(py::object o) {
    auto* p = new py::object(std::move(o));
    return std::shared_ptr<void>(static_cast<void*>(p), [](void* q) {
        if (!Py_IsInitialized()) return;  // interpreter gone: nothing left to release
        py::gil_scoped_acquire gil;
        delete static_cast<py::object*>(q);
    });
}

struct PyVolume {
    lacuna::Volume v;
    bool adopted = false;  // the voxels are the caller's array (no copy)
};

const char* numpy_name(lacuna::VoxelType t) {
    switch (t) {
        case lacuna::VoxelType::UInt8:
            return "uint8";
        case lacuna::VoxelType::Int16:
            return "int16";
        case lacuna::VoxelType::UInt16:
            return "uint16";
        default:
            return "float32";
    }
}

std::array<double, 3> triple(py::handle h, const std::string& where, const std::string& field) {
    std::vector<double> v;
    try {
        v = py::cast<std::vector<double>>(h);
    } catch (const py::cast_error&) {
        value_error(where, field, "expected three numbers");
    }
    if (v.size() != 3)
        value_error(where, field, "expected three numbers, got " + std::to_string(v.size()));
    return {v[0], v[1], v[2]};
}

// A 4x4 index-to-world affine (RAS mm, nibabel's convention) into Volume's LPS geometry.
void set_affine(lacuna::Volume& v, py::handle affine, const std::string& where) {
    py::array_t<double, py::array::c_style | py::array::forcecast> a;
    try {
        a = py::cast<py::array_t<double, py::array::c_style | py::array::forcecast>>(affine);
    } catch (const py::cast_error&) {
        value_error(where, "affine", "expected a 4x4 array of numbers");
    }
    if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
        value_error(where, "affine", "expected a 4x4 array");
    auto m = a.unchecked<2>();
    for (int c = 0; c < 4; ++c)
        if (m(3, c) != (c == 3 ? 1.0 : 0.0))
            value_error(where, "affine", "expected the last row 0, 0, 0, 1");
    const double flip[3] = {-1, -1, 1};  // RAS -> LPS
    for (int c = 0; c < 3; ++c) {
        const double len = std::sqrt(m(0, c) * m(0, c) + m(1, c) * m(1, c) + m(2, c) * m(2, c));
        v.spacing[c] = len;
        for (int r = 0; r < 3; ++r) v.direction[r * 3 + c] = len > 0 ? flip[r] * m(r, c) / len : 0;
    }
    v.origin = {flip[0] * m(0, 3), flip[1] * m(1, 3), flip[2] * m(2, 3)};
    v.geometry_source = "affine (Python)";
}

// The voxel type a numpy dtype is stored as: the four native ones as they are, the CLI readers'
// conversions (int8 -> int16; int32, uint32, float64 -> float32) with a copy.
lacuna::VoxelType voxel_type_of(const py::dtype& dt, const std::string& where) {
    const char kind = dt.kind();
    const auto size = dt.itemsize();
    if (kind == 'u' && size == 1) return lacuna::VoxelType::UInt8;
    if (kind == 'i' && size <= 2) return lacuna::VoxelType::Int16;
    if (kind == 'u' && size == 2) return lacuna::VoxelType::UInt16;
    if ((kind == 'f' && (size == 4 || size == 8)) || ((kind == 'i' || kind == 'u') && size == 4))
        return lacuna::VoxelType::Float32;
    value_error(where, "dtype",
                "expected uint8, int16, uint16 or float32 (int8, int32, uint32 and float64 are "
                "converted), got " +
                    py::str(py::handle(dt)).cast<std::string>());
}

std::shared_ptr<PyVolume> volume_from_array(py::object obj, py::object spacing, py::object affine,
                                            const std::string& axes, py::object range) {
    const std::string where = "array";
    py::module_ np = py::module_::import("numpy");
    py::array arr = np.attr("asarray")(obj);
    if (axes == "xyz")
        arr = arr.attr("T");
    else if (axes != "zyx")
        value_error(
            where, "axes",
            "expected 'zyx' (numpy/SimpleITK order) or 'xyz' (nibabel), got '" + axes + "'");
    if (arr.ndim() != 3)
        value_error(where, "shape",
                    "expected 3 axes (" + axes + "), got " + std::to_string(arr.ndim()));
    for (int a = 0; a < 3; ++a)
        if (arr.shape(a) < 2 || arr.shape(a) > lacuna::kMaxDim)
            value_error(where, "shape",
                        "expected 2.." + std::to_string(lacuna::kMaxDim) +
                            " voxels per axis, got " +
                            py::str(obj.attr("shape")).cast<std::string>());
    const lacuna::VoxelType type = voxel_type_of(arr.dtype(), where);
    const py::dtype target = py::dtype(numpy_name(type));
    // No copy: C order (x fastest, as lacuna::Volume stores voxels), aligned, the exact native
    // dtype. np.ascontiguousarray copies anything else (Fortran order, strides, byte order).
    const bool c_contiguous = (arr.flags() & py::array::c_style) != 0;
    const bool aligned = (arr.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) != 0;
    const bool adopt = c_contiguous && aligned && arr.dtype().equal(target);
    if (!adopt) arr = np.attr("ascontiguousarray")(arr, "dtype"_a = target);
    const lacuna::Vec3i dims{int(arr.shape(2)), int(arr.shape(1)), int(arr.shape(0))};
    void* data = const_cast<void*>(arr.data());
    auto out = std::make_shared<PyVolume>();
    out->adopted = adopt;
    out->v = lacuna::Volume(dims, type, hold(arr), data);
    if (!spacing.is_none() && !affine.is_none())
        value_error(where, "spacing", "give spacing or affine (which holds the spacing), not both");
    if (!spacing.is_none()) {
        const auto s = triple(spacing, where, "spacing");
        out->v.spacing = {s[0], s[1], s[2]};
    }
    if (!affine.is_none()) set_affine(out->v, affine, where);
    lacuna::check_geometry(out->v, where);
    {
        py::gil_scoped_release nogil;
        out->v.compute_range(where);
    }
    if (!range.is_none()) {
        const auto r = py::cast<std::pair<float, float>>(range);
        out->v.set_vis_range({r.first, r.second});
    }
    return out;
}

std::shared_ptr<PyVolume> load(const std::string& path, py::object dims, py::object dtype,
                               py::object spacing, py::object range, py::object max_memory,
                               bool allow_external_data, py::object frame) {
    lacuna::ReadOptions ro;
    if (!frame.is_none()) ro.frame = py::cast<int64_t>(frame);
    if (!dims.is_none() || !dtype.is_none()) {
        if (dims.is_none() || dtype.is_none())
            value_error(path, "raw layout", "give both dims and dtype for a raw file");
        const auto d = triple(dims, path, "dims");
        lacuna::RawSpec raw;
        raw.dims = {int(d[0]), int(d[1]), int(d[2])};
        raw.type = lacuna::parse_voxel_type(
            py::str(py::module_::import("numpy").attr("dtype")(dtype)).cast<std::string>(),
            "dtype");
        if (!spacing.is_none()) {
            const auto s = triple(spacing, path, "spacing");
            raw.spacing = {s[0], s[1], s[2]};
        }
        ro.raw = raw;
    } else if (!spacing.is_none()) {
        value_error(path, "spacing", "only raw files take a spacing (the others carry their own)");
    }
    if (!max_memory.is_none()) ro.max_memory.bytes = py::cast<uint64_t>(max_memory);
    ro.max_memory.name = "max_memory";
    ro.allow_external_data = allow_external_data;
    auto out = std::make_shared<PyVolume>();
    try {
        py::gil_scoped_release nogil;
        out->v = lacuna::read_volume(path, ro);
    } catch (const Error& e) {
        raise(PyExc_OSError, e.what());
    }
    if (!range.is_none()) {
        const auto r = py::cast<std::pair<float, float>>(range);
        out->v.set_vis_range({r.first, r.second});
    }
    return out;
}

// The voxels as a read-only numpy array of shape (z, y, x) over the Volume's own buffer; `self`
// (the Python Volume) is the array's base, so the buffer lives as long as the array.
py::array volume_array(py::object self) {
    const PyVolume& pv = self.cast<const PyVolume&>();
    const lacuna::Volume& v = pv.v;
    const lacuna::Vec3i d = v.dims();
    const auto size = py::ssize_t(lacuna::voxel_size(v.type()));
    py::array a(py::dtype(numpy_name(v.type())),
                {py::ssize_t(d.z), py::ssize_t(d.y), py::ssize_t(d.x)},
                {size * d.x * d.y, size * d.x, size}, v.data(), self);
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

py::array_t<double> affine_of(const lacuna::Volume& v) {
    const lacuna::Affine a = lacuna::index_to_world(v);
    py::array_t<double> out({4, 4});
    auto m = out.mutable_unchecked<2>();
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) m(r, c) = a.m[r][c];
        m(r, 3) = a.t[r];
    }
    for (int c = 0; c < 4; ++c) m(3, c) = c == 3 ? 1 : 0;
    return out;
}

// numpy.histogram's binning over [lo, hi] (equal bins, the last one closed): the same index
// formula and the same edge corrections, so the counts equal numpy's.
py::tuple histogram(const PyVolume& pv, int bins, py::object range) {
    if (bins < 1) value_error("histogram", "bins", "expected >= 1");
    const lacuna::ValueRange dr = pv.v.data_range();
    double lo = dr.min, hi = dr.max;
    if (!range.is_none()) std::tie(lo, hi) = py::cast<std::pair<double, double>>(range);
    if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi))
        value_error("histogram", "range", "expected finite lo <= hi");
    if (lo == hi) lo -= 0.5, hi += 0.5;  // numpy's widening of an empty range
    std::vector<double> edges(size_t(bins) + 1);
    const double step = (hi - lo) / bins;
    for (int i = 0; i <= bins; ++i) edges[size_t(i)] = lo + i * step;
    edges[size_t(bins)] = hi;
    std::vector<uint64_t> counts(size_t(bins), 0);
    {
        py::gil_scoped_release nogil;
        const double norm = bins / (hi - lo);
        lacuna::visit_voxels(pv.v, [&](const auto* p) {
            const size_t n = pv.v.voxel_count();
            for (size_t i = 0; i < n; ++i) {
                const double x = double(p[i]);
                if (x < lo || x > hi) continue;
                long k = long((x - lo) * norm);
                k = std::min<long>(k, bins - 1);
                if (x < edges[size_t(k)])
                    --k;
                else if (k != bins - 1 && x >= edges[size_t(k) + 1])
                    ++k;
                ++counts[size_t(k)];
            }
        });
    }
    return py::make_tuple(py::array_t<uint64_t>(py::ssize_t(bins), counts.data()),
                          py::array_t<double>(py::ssize_t(bins) + 1, edges.data()));
}

// ---- Transfer functions ------------------------------------------------------------------------
struct PyTf {
    lacuna::TransferFunction tf;
};

// A dict in the JSON format of docs/transfer-functions.md, checked by the JSON parser itself
// (the same rules and one-line errors as a .json file).
lacuna::TransferFunction tf_from_dict(py::dict d, const std::string& where) {
    py::module_ json = py::module_::import("json");
    std::string text;
    try {
        text = json.attr("dumps")(d, "allow_nan"_a = false).cast<std::string>();
    } catch (py::error_already_set& e) {
        value_error(where, "points", std::string("expected finite numbers (") + e.what() + ")");
    }
    return lacuna::parse_transfer_function(text, where);
}

lacuna::TransferFunction tf_from(py::handle h) {
    if (py::isinstance<PyTf>(h)) return h.cast<const PyTf&>().tf;
    if (py::isinstance<py::dict>(h)) return tf_from_dict(h.cast<py::dict>(), "TransferFunction");
    if (py::isinstance<py::str>(h) || py::hasattr(h, "__fspath__"))
        return lacuna::resolve_transfer_function(
            py::str(py::module_::import("os").attr("fspath")(h)).cast<std::string>());
    raise(PyExc_TypeError,
          "TransferFunction: expected a preset name, a .json or Slicer file, a dict or a "
          "TransferFunction");
}

py::dict tf_to_dict(const lacuna::TransferFunction& tf) {
    return py::module_::import("json").attr("loads")(lacuna::to_json(tf));
}

// ---- Sessions -----------------------------------------------------------------------------------
struct PySession {
    std::unique_ptr<lacuna::Session> session;
    std::mutex mutex;             // one frame at a time (lacuna::Session is not thread-safe)
    uint64_t tf_version = 0;      // bumped by every TF change through this object
    uint64_t refined_at = ~0ull;  // tf_version at the last refine()
    bool has_back = false;
};

// A kwargs reader that reports the keywords nobody read (a typo is an error, as a CLI flag is).
class Kwargs {
  public:
    explicit Kwargs(py::kwargs kw) : m_kw(std::move(kw)) {}
    bool has(const char* k) const { return m_kw.contains(k) && !m_kw[k].is_none(); }
    py::object get(const char* k) {
        m_used.push_back(k);
        return m_kw.contains(k) ? py::reinterpret_borrow<py::object>(m_kw[k]) : py::none();
    }
    template <class T>
    T get(const char* k, T fallback) {
        py::object o = get(k);
        if (o.is_none()) return fallback;
        try {
            return o.cast<T>();
        } catch (const py::cast_error&) {
            value_error(k, "type",
                        "expected " + py::type_id<T>() + ", got " +
                            py::str(o.get_type().attr("__name__")).cast<std::string>());
        }
    }
    std::vector<float> floats(const char* k, size_t n, size_t n_max = 0) {
        const std::vector<float> v = get<std::vector<float>>(k, {});
        for (float x : v)
            if (!std::isfinite(x)) value_error(k, "numbers", "expected finite numbers");
        if (v.size() < n || v.size() > std::max(n, n_max))
            value_error(k, "numbers",
                        "expected " + std::to_string(n) +
                            (n_max > n ? ".." + std::to_string(n_max) : std::string()) +
                            " numbers, got " + std::to_string(v.size()));
        return v;
    }
    void check_all_read(const char* what) const {
        for (auto item : m_kw) {
            const std::string k = py::str(item.first);
            if (std::find(m_used.begin(), m_used.end(), k) == m_used.end()) {
                std::string names;
                for (const std::string& u : m_used) names += (names.empty() ? "" : ", ") + u;
                value_error(what, k, "unknown keyword; expected one of: " + names);
            }
        }
    }

  private:
    py::kwargs m_kw;
    std::vector<std::string> m_used;
};

// The structure a name names for the renderer (lacuna::parse_structure, as the CLI and the viewer).
lacuna::Structure structure_from(const std::string& name, lacuna::Renderer r, Kwargs& kw) {
    lacuna::AccelOptions ao;
    ao.leaf_cells = kw.get<int>("leaf", 8);
    ao.bitfield_bits = kw.get<int>("bits", 64);
    ao.initial_level = kw.get<int>("initial_level", -1);
    ao.bidirectional = !kw.get<bool>("top_down", false);
    const lacuna::structure::GrowingBoxes boxes{kw.get<float>("coalesce", 0.25f),
                                                kw.get<float>("coalesce_edge", 64.f)};
    try {
        return lacuna::parse_structure(name, r, ao, boxes);  // the one parser of structure names
    } catch (const lacuna::FrameError& e) {
        value_error("structure", "structure", e.expected());
    }
}

lacuna::Light light_from(py::object o, float intensity) {
    lacuna::Light l;
    l.intensity = intensity;
    if (o.is_none() || (py::isinstance<py::str>(o) && o.cast<std::string>() == "head")) return l;
    if (!py::isinstance<py::dict>(o))
        value_error("light", "light",
                    "expected 'head', {'direction': (x, y, z)} or {'position': p, 'target': t, "
                    "'cone': degrees}");
    py::dict d = o.cast<py::dict>();
    auto vec = [&](const char* k) {
        const auto v = triple(d[k], "light", k);
        return lacuna::Vec3f{float(v[0]), float(v[1]), float(v[2])};
    };
    if (d.contains("direction")) {
        l.kind = lacuna::LightKind::Directional;
        l.direction = vec("direction");
    } else if (d.contains("position") && d.contains("target")) {
        l.kind = lacuna::LightKind::Spot;
        l.position = vec("position");
        l.target = vec("target");
        if (d.contains("cone")) l.cone_deg = d["cone"].cast<float>();
    } else {
        value_error("light", "light", "expected a 'direction', or a 'position' and a 'target'");
    }
    return l;
}

template <class E>
E enum_of(const std::string& s, const char* keyword,
          std::initializer_list<std::pair<const char*, E>> names) {
    std::string list;
    for (const auto& [n, e] : names) {
        if (s == n) return e;
        list += (list.empty() ? "" : ", ") + std::string(n);
    }
    value_error(keyword, "name", "unknown '" + s + "'; expected one of: " + list);
}

// The label table a frame starts from (before show/hide): the session's default table, or the
// CLI's --label-style over it: a .json label table or an MRIcron .lut file, or a dict in the JSON
// format (docs/segments.md), read by the same parser through a temporary .json file so that its
// rules and one-line errors are the file's, with "label_style" in place of the file name.
lacuna::LabelTable label_table_of(PySession& ps, py::object style) {
    if (style.is_none()) {
        py::gil_scoped_release nogil;
        std::lock_guard<std::mutex> lock(ps.mutex);
        return ps.session->label_table();
    }
    auto load = [&](const std::string& path) {
        py::gil_scoped_release nogil;
        std::lock_guard<std::mutex> lock(ps.mutex);
        return lacuna::load_label_table(path, ps.session->label_volume());
    };
    if (py::isinstance<py::str>(style) || py::hasattr(style, "__fspath__")) {
        const std::string path =
            py::str(py::module_::import("os").attr("fspath")(style)).cast<std::string>();
        if (!std::filesystem::is_regular_file(path))
            raise(PyExc_OSError, path + ": file: does not exist");
        return load(path);
    }
    if (!py::isinstance<py::dict>(style))
        value_error("label_style", "type",
                    "expected a .json or .lut file or a dict {'labels': [{'label': 1, ...}, ...]}");
    std::string text;
    try {
        text = py::module_::import("json")
                   .attr("dumps")(style, "allow_nan"_a = false)
                   .cast<std::string>();
    } catch (py::error_already_set& e) {
        value_error("label_style", "labels",
                    std::string("expected JSON values (") + e.what() + ")");
    }
    py::module_ tempfile = py::module_::import("tempfile");
    py::object dir = tempfile.attr("TemporaryDirectory")();
    const std::string path = py::str(dir.attr("name")).cast<std::string>() + "/label_style.json";
    try {
        {
            std::ofstream out(path, std::ios::binary);
            out << text;
        }
        lacuna::LabelTable t = load(path);
        dir.attr("cleanup")();
        return t;
    } catch (const Error& e) {
        dir.attr("cleanup")();
        std::string m = e.what();
        if (m.rfind(path, 0) == 0) m = "label_style" + m.substr(path.size());
        raise(PyExc_ValueError, m);
    }
}

struct Request {
    lacuna::FrameSpec spec;
    bool refine = true;
    bool float32 = false;
};

// render()'s keywords -> a FrameSpec. Defaults are `lacuna render`'s (docs/cli.md) except the
// size: 512 x 512.
Request request_from(PySession& ps, py::kwargs kwargs) {
    Kwargs kw(std::move(kwargs));
    Request req;
    lacuna::FrameSpec& f = req.spec;
    using lacuna::Renderer;
    const std::string renderer = kw.get<std::string>("renderer", "march");
    f.renderer = enum_of<Renderer>(renderer, "renderer",
                                   {{"march", Renderer::RayMarcher},
                                    {"slice", Renderer::Slicer},
                                    {"segments", Renderer::Segments}});
    const int size = kw.get<int>("size", 512);
    f.width = kw.get<int>("width", size);
    f.height = kw.get<int>("height", size);
    // Camera: a named view, or azimuth/elevation, or an eye and a target.
    lacuna::OrbitParams& o = f.camera.orbit;
    o.azimuth_deg = 30.f;
    o.elevation_deg = 15.f;
    const bool angles = kw.has("azimuth") || kw.has("elevation");
    if (kw.has("view")) {
        const std::string view = kw.get<std::string>("view", "");
        if (angles)
            value_error("view", "view", "sets the azimuth and elevation; drop azimuth/elevation");
        if (!lacuna::named_view(view, o.azimuth_deg, o.elevation_deg))
            value_error("view", "view",
                        std::string("expected ") + lacuna::kViewNames + ", got '" + view + "'");
    } else {
        kw.get("view");
    }
    o.azimuth_deg = kw.get<float>("azimuth", o.azimuth_deg);
    o.elevation_deg = kw.get<float>("elevation", o.elevation_deg);
    if (kw.has("eye")) {
        if (angles || kw.has("view"))
            value_error("eye", "camera", "give eye/target or view/azimuth/elevation");
        const auto e = triple(kw.get("eye"), "eye", "position");
        const lacuna::Box3f b = ps.session->bounds();
        lacuna::Vec3f t = b.center();
        if (kw.has("target")) {
            const auto tt = triple(kw.get("target"), "target", "position");
            t = {float(tt[0]), float(tt[1]), float(tt[2])};
            o.has_target = true;
            o.target = t;
        }
        const lacuna::Vec3f d{float(e[0]) - t.x, float(e[1]) - t.y, float(e[2]) - t.z};
        const float len = lacuna::length(d);
        if (!(len > 0) || !std::isfinite(len))
            value_error("eye", "position", "expected an eye away from the target");
        // Camera::orbit's to_eye = (-sin az cos el, cos az cos el, sin el).
        o.elevation_deg = float(std::asin(std::clamp(d.z / len, -1.f, 1.f)) * 180.0 / M_PI);
        o.azimuth_deg = float(std::atan2(-d.x, d.y) * 180.0 / M_PI);
        o.distance = len;
    } else {
        kw.get("eye");
        if (kw.has("target")) {
            const auto tt = triple(kw.get("target"), "target", "position");
            o.has_target = true;
            o.target = {float(tt[0]), float(tt[1]), float(tt[2])};
        }
    }
    kw.get("target");  // read above when given
    // The image's up (any camera): superior unless given; validate() refuses one that is not
    // finite or lies along the view direction.
    if (kw.has("up")) {
        const auto u = triple(kw.get("up"), "up", "direction");
        o.up = {float(u[0]), float(u[1]), float(u[2])};
    } else {
        kw.get("up");
    }
    o.zoom = kw.get<float>("zoom", 1.f);
    o.fov_y_deg = kw.get<float>("fov", 30.f);
    o.projection = kw.get<bool>("ortho", false) ? lacuna::Projection::Orthographic
                                                : lacuna::Projection::Perspective;
    if (kw.has("pan")) {
        const auto p = kw.get<std::pair<float, float>>("pan", {0.f, 0.f});
        f.camera.pan_x = p.first;
        f.camera.pan_y = p.second;
    } else {
        kw.get("pan");
    }
    // Sampling.
    f.sampling.step = kw.get<float>("step", 0.5f);
    // ert=1 turns early termination off (the CLI's --ert 1).
    const float ert = kw.get<float>("ert", 0.99f);
    f.sampling.early_termination = ert == 1.f ? std::nullopt : std::optional<float>(ert);
    try {
        f.sampling.interpolation =
            lacuna::parse_interpolation(kw.get<std::string>("interpolation", "trilinear"));
    } catch (const Error&) {
        value_error("interpolation", "interpolation", "expected trilinear or nearest");
    }
    if (kw.has("background")) {
        const auto b = triple(kw.get("background"), "background", "colour");
        f.background = {float(b[0]), float(b[1]), float(b[2])};
    } else {
        kw.get("background");
    }
    // Features (FeatureOptions, docs/shading.md).
    lacuna::FeatureOptions& ft = f.features;
    using lacuna::ShadingModel;
    ft.shading = enum_of<ShadingModel>(
        kw.get<std::string>("shading", "none"), "shading",
        {{"none", ShadingModel::None}, {"phong", ShadingModel::Phong}, {"pbr", ShadingModel::Pbr}});
    if (kw.has("phong")) {
        const auto v = kw.floats("phong", 4);
        ft.phong = {v[0], v[1], v[2], v[3]};
    } else {
        kw.get("phong");
    }
    if (kw.has("pbr")) {
        const auto v = kw.floats("pbr", 2, 3);
        ft.pbr.roughness = v[0];
        ft.pbr.metallic = v[1];
        if (v.size() == 3) ft.pbr.ambient = v[2];
    } else {
        kw.get("pbr");
    }
    ft.gradient = kw.get<bool>("gradient_volume", false) ? lacuna::GradientSource::Precomputed
                                                         : lacuna::GradientSource::OnTheFly;
    if (kw.has("gradient_opacity")) {
        const auto v = kw.floats("gradient_opacity", 2);
        ft.gradient_opacity.enabled = true;
        ft.gradient_opacity.lo = v[0];
        ft.gradient_opacity.hi = v[1];
    } else {
        kw.get("gradient_opacity");
    }
    const float intensity = kw.get<float>("light_intensity", 1.f);
    ft.light = light_from(kw.get("light"), intensity);
    ft.shadows.enabled = kw.get<bool>("shadows", false);
    ft.shadows.accelerate = !kw.get<bool>("unaccelerated_shadows", false);
    ft.shadows.step = kw.get<float>("shadow_step", 1.f);
    ft.shadows.light_volume = kw.get<bool>("light_volume", false);
    ft.shadows.light_volume_stride = kw.get<int>("light_volume_stride", 2);
    if (kw.has("clip")) {
        py::object c = kw.get("clip");
        std::vector<std::vector<float>> planes;
        try {
            planes = c.cast<std::vector<std::vector<float>>>();
        } catch (const py::cast_error&) {
            planes = {c.cast<std::vector<float>>()};  // one plane (nx, ny, nz, d)
        }
        for (const auto& p : planes) {
            if (p.size() != 4) value_error("clip", "plane", "expected (nx, ny, nz, d) per plane");
            ft.clip_planes.push_back({{p[0], p[1], p[2]}, p[3]});
        }
    } else {
        kw.get("clip");
    }
    if (kw.has("crop")) {
        const auto v = kw.floats("crop", 6);
        ft.crop = true;
        ft.crop_box = {{v[0], v[2], v[4]}, {v[1], v[3], v[5]}};
    } else {
        kw.get("crop");
    }
    using lacuna::BlendMode;
    ft.blend = enum_of<BlendMode>(kw.get<std::string>("blend", "composite"), "blend",
                                  {{"composite", BlendMode::Composite},
                                   {"mip", BlendMode::Mip},
                                   {"minip", BlendMode::MinIp},
                                   {"average", BlendMode::Average}});
    ft.jitter = kw.get<bool>("jitter", false);
    ft.jitter_seed = kw.get<uint32_t>("jitter_seed", 0);
    f.two_tfs = ps.has_back;
    // The slicer's and the segments' options.
    f.slicer.occlusion = kw.get<bool>("occlusion", false);
    f.slicer.occlusion_threshold = kw.get<float>("occlusion_threshold", 0.95f);
    f.slicer.occlusion_map = kw.get<int>("occlusion_map", 64);
    if (f.renderer == Renderer::Segments) {
        f.segments.mode =
            lacuna::parse_segment_mode(kw.get<std::string>("segments", "mask"), "segments");
        f.segments.tint = kw.get<float>("label_tint", 0.f);
        lacuna::LabelTable table = label_table_of(ps, kw.get("label_style"));
        auto visibility = [&](const char* k, bool visible) {
            py::object o = kw.get(k);
            if (o.is_none()) return;
            std::string spec;
            if (py::isinstance<py::str>(o)) {
                spec = o.cast<std::string>();
            } else {
                for (int label : o.cast<std::vector<int>>())
                    spec += (spec.empty() ? "" : ",") + std::to_string(label);
            }
            if (!spec.empty()) lacuna::set_label_visibility(table, spec, visible, k);
        };
        visibility("show", true);
        visibility("hide", false);
        f.segments.labels = table;
    } else {
        for (const char* k : {"segments", "label_tint", "label_style", "show", "hide"})
            if (kw.has(k))
                value_error(k, "renderer", "only renderer='segments' takes it");
            else
                kw.get(k);
    }
    f.structure = structure_from(kw.get<std::string>("structure", "auto"), f.renderer, kw);
    f.count_samples = kw.get<bool>("sample_counts", false);
    req.refine = kw.get<bool>("refine", true);
    const std::string dtype = py::str(py::module_::import("numpy").attr("dtype")(
                                          kw.has("dtype") ? kw.get("dtype") : py::str("uint8")))
                                  .cast<std::string>();
    if (!kw.has("dtype")) kw.get("dtype");
    if (dtype != "uint8" && dtype != "float32")
        value_error("dtype", "dtype", "expected uint8 or float32, got " + dtype);
    req.float32 = dtype == "float32";
    f.keep_float = req.float32;  // the renderer's values before the 8-bit rounding
    kw.check_all_read("render");
    try {
        lacuna::validate(f);
    } catch (const lacuna::FrameError& e) {
        raise(PyExc_ValueError, python_message(e));
    }
    return req;
}

py::dict stats_of(const lacuna::FrameResult& r) {
    py::dict d;
    d["seconds"] = r.stats.seconds;
    d["cpu_seconds"] = r.stats.cpu_seconds;
    d["samples"] = r.stats.samples;
    d["rays"] = r.stats.rays;
    d["pixels"] = r.stats.pixels;
    d["samples_per_ray"] = r.stats.samples_per_ray();
    d["msamples_per_second"] = r.stats.msamples_per_second();
    d["shadow_samples"] = r.stats.shadow_samples;
    d["build_seconds"] = r.build_seconds;
    d["tf_sync_seconds"] = r.tf_sync_seconds;
    if (r.structure) {
        d["structure_bytes"] = r.structure->bytes;
        d["structure_nodes"] = r.structure->nodes;
        d["structure_build_seconds"] = r.structure->build_seconds;
        d["tf_update_seconds"] = r.structure->tf_update_seconds;
        d["refine_seconds"] = r.structure->refine_seconds;
    }
    if (r.slicer) d["skipped_fraction"] = r.slicer->skipped_fraction;
    if (r.segments) d["label_octree_bytes"] = r.segments->bytes;
    return d;
}

// The image as an H x W x 4 numpy array over the result's own buffer (moved, not copied).
py::array image_array(lacuna::Image&& img) {
    auto* bytes = new std::vector<uint8_t>(std::move(img.rgba));
    py::capsule owner(bytes, [](void* p) { delete static_cast<std::vector<uint8_t>*>(p); });
    return py::array_t<uint8_t>({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(4)},
                                bytes->data(), owner);
}

// The reference count of the "skipped share" (the viewer's figure, src/serve/frame_renderer.cpp):
// the samples of the lattice march without skipping or early termination for this frame's
// camera. It costs a ray set-up per pixel, so Frame.stats computes it when first read, not inside
// render(). The volume copy shares the voxels.
struct LatticeCount {
    lacuna::Volume volume;  // the lattice's volume: the label map for the segment renderer
    lacuna::Camera camera;
    float step = 0.5f;
    int threads = 0;
    uint64_t operator()() const {
        py::gil_scoped_release nogil;
        return lacuna::count_lattice_samples(volume, camera, step, threads);
    }
};

// (image, image8, stats, sample_counts, lattice): image is the requested dtype (float32: the
// renderer's premultiplied RGBA before the background and the rounding), image8 the 8-bit image
// (the CLI's bytes), lattice a callable giving the lattice count (None for the slicer, whose
// stats carry the Session's own skipped share).
py::tuple render(PySession& ps, py::kwargs kwargs) {
    const Request req = request_from(ps, std::move(kwargs));
    lacuna::FrameResult r;
    std::optional<LatticeCount> lattice;
    {
        py::gil_scoped_release nogil;
        std::lock_guard<std::mutex> lock(ps.mutex);
        // The CLI's order (cmd_render.cpp): build, the finer per-TF level, then the frame.
        const lacuna::FrameResult built = ps.session->prepare(req.spec);
        if (req.refine && req.spec.renderer != lacuna::Renderer::Segments &&
            ps.refined_at != ps.tf_version) {
            ps.session->refine();
            ps.refined_at = ps.tf_version;
        }
        r = ps.session->render(req.spec);
        r.build_seconds += built.build_seconds;  // what this call built, before the frame
        r.tf_sync_seconds += built.tf_sync_seconds;
        if (req.spec.renderer != lacuna::Renderer::Slicer)
            lattice = LatticeCount{
                req.spec.renderer == lacuna::Renderer::Segments ? ps.session->label_volume()
                                                                : ps.session->volume(),
                ps.session->camera(req.spec), req.spec.sampling.step, ps.session->threads()};
    }
    py::dict stats = stats_of(r);
    py::array image8 = image_array(std::move(r.image));
    py::array image = image8;
    if (req.float32) {
        auto* values = new std::vector<float>(std::move(r.rgba_float));
        py::capsule owner(values, [](void* p) { delete static_cast<std::vector<float>*>(p); });
        image = py::array_t<float>(
            {py::ssize_t(req.spec.height), py::ssize_t(req.spec.width), py::ssize_t(4)},
            values->data(), owner);
    }
    py::object counts = py::none();
    if (req.spec.count_samples)
        counts = py::array_t<uint32_t>({py::ssize_t(req.spec.height), py::ssize_t(req.spec.width)},
                                       r.sample_counts.data());
    py::object count = py::none();
    if (lattice) count = py::cpp_function([l = *lattice]() { return l(); });
    return py::make_tuple(image, image8, stats, counts, count);
}

void set_tf(PySession& ps, py::handle tf) {
    const lacuna::TransferFunction t = tf_from(tf);
    py::gil_scoped_release nogil;
    std::lock_guard<std::mutex> lock(ps.mutex);
    if (ps.session->set_transfer_function(t)) ++ps.tf_version;
}

void set_back_tf(PySession& ps, py::handle tf) {
    std::optional<lacuna::TransferFunction> t;
    if (!tf.is_none()) t = tf_from(tf);
    py::gil_scoped_release nogil;
    std::lock_guard<std::mutex> lock(ps.mutex);
    ps.session->set_back_transfer_function(t);
    ps.has_back = t.has_value();
    ++ps.tf_version;
}

}  // namespace

PYBIND11_MODULE(_lacuna, m) {
    m.doc() =
        "lacuna: CPU direct volume rendering with exact empty-space skipping (docs/python.md)";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const lacuna::FrameError& e) {
            PyErr_SetString(PyExc_ValueError, python_message(e).c_str());
        } catch (const Error& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });

    py::class_<PyVolume, std::shared_ptr<PyVolume>>(m, "Volume", R"(A scalar volume.

Volume(array, spacing=None, affine=None, axes='zyx', range=None)
  array: 3 axes, numpy order (z, y, x) by default (axes='xyz' for nibabel's (i, j, k));
  uint8, int16, uint16 or float32 (int8 -> int16; int32, uint32, float64 -> float32, copied).
  A C-contiguous array of one of the four types is adopted without a copy (with axes='xyz':
  a Fortran-ordered one); the Volume keeps it alive. Do not write to it afterwards.
  spacing: (x, y, z) mm; affine: 4x4 index-to-world (RAS mm, nibabel's img.affine).
  range: the visualization range (min, max) the TF's [0, 1] spans (default: the data range).)")
        .def(py::init(&volume_from_array), "array"_a, "spacing"_a = py::none(),
             "affine"_a = py::none(), "axes"_a = "zyx", "range"_a = py::none())
        .def_property_readonly(
            "shape",
            [](const PyVolume& p) {
                const auto d = p.v.dims();
                return py::make_tuple(d.z, d.y, d.x);
            },
            "(z, y, x), the shape of .array")
        .def_property_readonly(
            "dims",
            [](const PyVolume& p) {
                const auto d = p.v.dims();
                return py::make_tuple(d.x, d.y, d.z);
            },
            "(x, y, z) voxels")
        .def_property_readonly("dtype",
                               [](const PyVolume& p) { return py::dtype(numpy_name(p.v.type())); })
        .def_property_readonly(
            "spacing",
            [](const PyVolume& p) {
                return py::make_tuple(p.v.spacing.x, p.v.spacing.y, p.v.spacing.z);
            },
            "(x, y, z) mm between voxel centres")
        .def_property_readonly(
            "affine", [](const PyVolume& p) { return affine_of(p.v); },
            "4x4 index-to-world (RAS mm)")
        .def_property_readonly("orientation",
                               [](const PyVolume& p) { return lacuna::orientation_code(p.v); })
        .def_property_readonly(
            "range",
            [](const PyVolume& p) {
                return py::make_tuple(p.v.data_range().min, p.v.data_range().max);
            },
            "(min, max) of the voxel values")
        .def_property(
            "vis_range",
            [](const PyVolume& p) {
                return py::make_tuple(p.v.vis_range().min, p.v.vis_range().max);
            },
            [](PyVolume& p, std::pair<float, float> r) {
                p.v.set_vis_range({r.first, r.second});
            },
            "the visualization range the TF's [0, 1] spans")
        .def_property_readonly(
            "zero_copy", [](const PyVolume& p) { return p.adopted; },
            "True when the voxels are the array given to Volume() (no copy)")
        .def_property_readonly("array", &volume_array,
                               "the voxels, read-only, shape (z, y, x), no copy")
        .def(
            "__array__",
            [](py::object self, py::object dtype, py::object) {
                py::array a = volume_array(self);
                return dtype.is_none() ? a : py::array(a.attr("astype")(dtype));
            },
            "dtype"_a = py::none(), "copy"_a = py::none())
        .def("histogram", &histogram, "bins"_a = 256, "range"_a = py::none(),
             "(counts, edges) as numpy.histogram(volume.array, bins, range or volume.range)")
        .def("__repr__",
             [](const PyVolume& p) { return "<lacuna.Volume " + lacuna::to_string(p.v) + ">"; });

    m.def(
        "load", &load, "path"_a, "dims"_a = py::none(), "dtype"_a = py::none(),
        "spacing"_a = py::none(), "range"_a = py::none(), "max_memory"_a = py::none(),
        "allow_external_data"_a = false, "frame"_a = py::none(),
        R"(Reads a volume file as the CLI does: .nii/.nii.gz, .nrrd/.nhdr, .mha/.mhd, a DICOM folder,
or .raw (dims=(x, y, z) and dtype, or a name like head_256x256x128_uint8.raw). frame=N picks the
volume of a 4D NIfTI file (required when it holds several). Raises OSError with the reader's
one-line message.)");

    py::class_<PyTf>(m, "TransferFunction", R"(A transfer function.

TransferFunction(spec) with spec a preset name (lacuna.presets()), a .json file, a Slicer preset
('slicer:presets.xml#CT-AAA', file.vp, file.vp.json), or a dict in the JSON format of
docs/transfer-functions.md; or TransferFunction(color=[(x, r, g, b), ...],
opacity=[(x, a), ...], domain='normalized', range=None, name='python').)")
        .def(py::init([](py::object spec, py::object color, py::object opacity,
                         const std::string& domain, py::object range, const std::string& name) {
                 if (!spec.is_none()) {
                     if (!color.is_none() || !opacity.is_none())
                         value_error("TransferFunction", "spec", "give a spec or points, not both");
                     return PyTf{tf_from(spec)};
                 }
                 py::dict d;
                 d["name"] = name;
                 d["domain"] = domain;
                 d["color"] = color;
                 d["opacity"] = opacity;
                 d["range"] = range;
                 if (color.is_none()) d.attr("pop")("color");
                 if (opacity.is_none()) d.attr("pop")("opacity");
                 return PyTf{tf_from_dict(d, "TransferFunction")};
             }),
             "spec"_a = py::none(), py::kw_only(), "color"_a = py::none(), "opacity"_a = py::none(),
             "domain"_a = "normalized", "range"_a = py::none(), "name"_a = "python")
        .def_property_readonly("name", [](const PyTf& t) { return t.tf.name; })
        .def_property_readonly("domain",
                               [](const PyTf& t) { return lacuna::to_string(t.tf.domain); })
        .def_property(
            "color",
            [](const PyTf& t) {
                py::list l;
                for (const auto& c : t.tf.color) l.append(py::make_tuple(c.x, c.r, c.g, c.b));
                return l;
            },
            [](PyTf& t, py::object points) {
                py::dict d = tf_to_dict(t.tf);
                d["color"] = points;
                t.tf = tf_from_dict(d, "TransferFunction");
            })
        .def_property(
            "opacity",
            [](const PyTf& t) {
                py::list l;
                for (const auto& o : t.tf.opacity) l.append(py::make_tuple(o.x, o.a));
                return l;
            },
            [](PyTf& t, py::object points) {
                py::dict d = tf_to_dict(t.tf);
                d["opacity"] = points;
                t.tf = tf_from_dict(d, "TransferFunction");
            })
        .def_property(
            "range",
            [](const PyTf& t) -> py::object {
                if (!t.tf.range) return py::none();
                return py::make_tuple(t.tf.range->min, t.tf.range->max);
            },
            [](PyTf& t, py::object r) {
                py::dict d = tf_to_dict(t.tf);
                d["range"] = r;
                t.tf = tf_from_dict(d, "TransferFunction");
            })
        .def("to_json", [](const PyTf& t) { return lacuna::to_json(t.tf); })
        .def("to_dict", [](const PyTf& t) { return tf_to_dict(t.tf); })
        .def("__eq__", [](const PyTf& a, const PyTf& b) { return a.tf == b.tf; })
        .def("__repr__", [](const PyTf& t) {
            return "<lacuna.TransferFunction " + lacuna::to_string(t.tf) + ">";
        });
    m.def("presets", &lacuna::preset_names, "the built-in TF presets' names");
    m.def(
        "structures",
        [] {
            std::vector<std::string> names{"auto"};
            for (const auto& n : lacuna::accel_names()) names.push_back(n);
            names.push_back("boxes");
            names.push_back("label-octree");
            return names;
        },
        "the structure names render(structure=...) takes");

    py::class_<PySession>(m, "_Session")
        .def(py::init([](const PyVolume& v, int threads) {
                 auto ps = std::make_unique<PySession>();
                 ps->session = std::make_unique<lacuna::Session>(v.v, threads);
                 return ps;
             }),
             "volume"_a, "threads"_a = 0)
        .def("set_transfer_function", &set_tf, "tf"_a)
        .def("set_back_transfer_function", &set_back_tf, "tf"_a)
        .def("transfer_function",
             [](PySession& ps) -> py::object {
                 if (!ps.session->has_transfer_function()) return py::none();
                 return py::cast(PyTf{ps.session->transfer_function()});
             })
        .def("set_labels",
             [](PySession& ps, const PyVolume& labels) {
                 py::gil_scoped_release nogil;
                 std::lock_guard<std::mutex> lock(ps.mutex);
                 ps.session->set_labels(labels.v);
             })
        .def(
            "label_table",
            [](PySession& ps, py::object style) {
                py::list out;
                const lacuna::LabelTable t = label_table_of(ps, style);
                for (int l = 0; l < t.size(); ++l) {
                    const lacuna::LabelStyle& st = t.styles[size_t(l)];
                    out.append(py::dict("label"_a = l, "name"_a = st.name,
                                        "color"_a = py::make_tuple(st.r, st.g, st.b),
                                        "opacity"_a = st.opacity, "visible"_a = st.visible));
                }
                return out;
            },
            "label_style"_a = py::none())
        .def("volume",
             [](PySession& ps) {
                 auto v = std::make_shared<PyVolume>();
                 v->v = ps.session->volume();  // shares the voxels
                 return v;
             })
        .def("render", &render)
        .def("built_count",
             [](PySession& ps) {
                 std::lock_guard<std::mutex> lock(ps.mutex);
                 return ps.session->built_count();
             })
        .def("drop_structures", [](PySession& ps) {
            py::gil_scoped_release nogil;
            std::lock_guard<std::mutex> lock(ps.mutex);
            ps.session->drop_structures();
        });

    m.def(
        "save_png",
        [](const std::string& path,
           py::array_t<uint8_t, py::array::c_style | py::array::forcecast> img) {
            if (img.ndim() != 3 || img.shape(2) != 4)
                value_error(path, "image", "expected an H x W x 4 uint8 array");
            lacuna::Image out(int(img.shape(1)), int(img.shape(0)));
            std::memcpy(out.rgba.data(), img.data(), out.rgba.size());
            try {
                py::gil_scoped_release nogil;
                lacuna::write_png(path, out);
            } catch (const Error& e) {
                raise(PyExc_OSError, e.what());
            }
        },
        "path"_a, "image"_a,
        "Writes an H x W x 4 uint8 image as a PNG (atomically, as the CLI does)");
    m.def(
        "read_png",
        [](const std::string& path) {
            lacuna::Image img;
            try {
                img = lacuna::read_png(path);
            } catch (const Error& e) {
                raise(PyExc_OSError, e.what());
            }
            return image_array(std::move(img));
        },
        "path"_a, "Reads an 8-bit RGB/RGBA PNG as an H x W x 4 uint8 array");
}
