#include "bench/faludi.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "bench/report.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
#include "render/sample_analysis.h"

namespace lacuna::bench {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

RenderOptions render_options(const FaludiOptions& o, RowMode m, const Box3f& bounds) {
    return row_render_options(o, m, bounds);
}

// A row's orbit through `k` as the session renders it: the row's render options (sampling,
// shading, the spotlight and its shadows) as a FrameSpec, one per view.
std::vector<FrameSpec> row_frames(const FaludiOptions& o, RowMode m, const Session& session,
                                  AccelKind k) {
    const RenderOptions ro = render_options(o, m, session.bounds());
    FrameSpec base;
    base.renderer = Renderer::RayMarcher;
    base.structure = structure_of(k, o.accel);
    base.sampling.step = ro.step;
    base.sampling.interpolation = ro.interpolation;
    base.sampling.early_termination =
        ro.ert < 1.f ? std::optional<float>(ro.ert) : std::optional<float>{};
    base.features = ro.features;
    return orbit_frames(base, o.orbit);
}

// Builds a structure through the session (its first frame's prepare) and times its TF
// changes. Every structure in lacuna recomputes its whole TF-dependent part on each change
// (none caches the previous LUT); the session syncs a structure lazily, so a repeat sets the
// same TF under another name and then the dataset's own again, and times the one sync that
// brings the structure back to it.
StructureResult build_structure(AccelKind k, const BenchDataset& d, const FaludiOptions& o,
                                Session& session, const FrameSpec& frame) {
    StructureResult s;
    s.kind = k;
    const FrameResult built = session.prepare(frame);
    s.generation_ms = (built.build_seconds + built.tf_sync_seconds) * 1e3;
    s.build_ms = built.structure ? built.structure->build_seconds * 1e3 : 0;
    std::vector<double> tf;
    if (built.structure) tf.push_back(built.structure->tf_update_seconds * 1e3);
    TransferFunction other = d.tf;  // the same LUT under another name: a change to the session
    other.name += " (again)";
    for (int r = 1; r < std::max(1, o.tf_repeats); ++r) {
        session.set_transfer_function(other);
        session.set_transfer_function(d.tf);
        const FrameResult again = session.prepare(frame);
        if (again.structure) tf.push_back(again.structure->tf_update_seconds * 1e3);
    }
    s.tf_change_ms = tf.empty() ? 0 : percentile(tf, 50);
    if (o.refine) {
        session.refine();
        if (const Accel* a = session.built_structure(frame))
            s.refine_ms = a->stats().refine_seconds * 1e3;
    }
    if (const Accel* a = session.built_structure(frame)) {
        s.bytes = a->stats().bytes;
        s.nodes = a->stats().nodes;
    }
    return s;
}

// One cell of the table; compares view 0 with `reference` (none's), or hands view 0 back in
// `first` (for none itself).
CellResult run_cell(AccelKind k, Session& session, const std::vector<FrameSpec>& frames,
                    const Image* reference, Image* first = nullptr) {
    OrbitRun run = run_orbit(session, frames);
    if (first) *first = std::move(run.first_image);
    CellResult c;
    c.kind = k;
    std::vector<double> ms;
    for (double s : run.frame_seconds) ms.push_back(s * 1e3);
    c.frame_ms = summarize(ms);
    c.samples = run.samples;
    c.rays = run.rays;
    c.exact = !reference || run.first_image.rgba == reference->rgba;
    return c;
}

void log_cell(const LogFn& log, const DatasetResult& d, const RowResult& row, const CellResult& c) {
    if (!log) return;
    char line[512];
    std::snprintf(line, sizeof line,
                  "  %-16s %-14s %-10s mean %9.2f ms  p99 %9.2f ms  %7.1f samples/ray  %6.2fx",
                  d.name.c_str(), to_string(row.mode).c_str(), to_string(c.kind).c_str(),
                  c.frame_ms.mean, c.frame_ms.p99, c.samples_per_ray(), c.speedup);
    std::string s = line;
    if (row.ideal_samples && c.kind != AccelKind::None)
        s += " (" + fmt("%.0f", 100 * row.share_of_ideal(c.kind)) + "% of ideal)";
    log(s + "  exact " + (c.exact ? "yes" : "NO"));
}

DatasetResult run_dataset(const BenchDataset& d, const FaludiOptions& o, const LogFn& log) {
    DatasetResult out;
    out.name = d.name;
    out.description = d.description;
    out.tf_name = d.tf_name;
    out.dims = d.volume->dims();
    out.type = d.volume->type();
    out.spacing = d.volume->spacing;

    // Every cell renders through one session (as every front end does): each structure is built
    // by its first frame's prepare() and dropped after its rows.
    Session session(*d.volume, o.threads);  // shares the voxels
    session.set_transfer_function(d.tf);
    const Box3f bounds = session.bounds();
    std::vector<Camera> cams;
    for (const FrameSpec& f : row_frames(o, o.modes[0], session, AccelKind::None))
        cams.push_back(session.camera(f));
    const std::vector<AccelKind> kinds = bench_columns(o.accels);

    // 1. The reference rows (none) and their view-0 images.
    std::vector<Image> reference;
    for (RowMode mode : o.modes) {
        RowResult row;
        row.mode = mode;
        row.ert = render_options(o, mode, bounds).ert;
        out.rows.push_back(row);
    }
    out.structures.push_back(StructureResult{});
    for (RowResult& row : out.rows) {
        if (log) log("  " + d.name + " " + to_string(row.mode) + " none ...");
        reference.push_back(Image{});
        CellResult c =
            run_cell(AccelKind::None, session, row_frames(o, row.mode, session, AccelKind::None),
                     nullptr, &reference.back());
        c.exact = true;
        c.speedup = c.sample_reduction = 1;
        row.cells.push_back(c);
    }

    // 2. The ideal: visible-cell samples over the same orbit.
    {
        const auto t0 = std::chrono::steady_clock::now();
        const VisibleCells cells(*d.volume, d.lut, o.threads);
        out.visible_cell_fraction = cells.visible_fraction();
        if (o.ideal) {
            for (RowResult& row : out.rows) {
                const auto t1 = std::chrono::steady_clock::now();
                const RenderOptions ro = render_options(o, row.mode, bounds);
                // Shading and lighting change what a sample costs, not which samples a ray
                // takes: their ideal is that of the early-exit row.
                const RowResult* same = nullptr;
                for (const RowResult& other : out.rows)
                    if (&other != &row && other.ert == row.ert && other.ideal_samples &&
                        other.mode == RowMode::EarlyExit)
                        same = &other;
                if (same && row.mode != RowMode::EarlyExit) {
                    row.ideal_samples = same->ideal_samples;
                    continue;
                }
                for (const Camera& cam : cams)
                    row.ideal_samples +=
                        count_visible_cell_samples(*d.volume, d.lut, cells, cam, ro);
                row.ideal_seconds = ms_since(t1) * 1e-3;
            }
        }
        if (log) {
            std::string line = "  " + d.name + ": " + fmt("%.2f", 100 * out.visible_cell_fraction) +
                               "% of cells visible";
            for (const RowResult& row : out.rows)
                if (row.ideal_samples)
                    line += "; " + to_string(row.mode) + " ideal speedup " +
                            fmt("%.2f", row.ideal_speedup()) + "x";
            log(line + " (" + fmt("%.1f", ms_since(t0)) + " ms)");
        }
    }
    for (RowResult& row : out.rows) log_cell(log, out, row, row.cells[0]);

    // 3. Every structure: build, time TF changes, render each row, compare view 0.
    for (AccelKind k : kinds) {
        if (k == AccelKind::None) continue;
        const StructureResult s =
            build_structure(k, d, o, session, row_frames(o, o.modes[0], session, k)[0]);
        out.structures.push_back(s);
        if (log) {
            char line[256];
            std::snprintf(
                line, sizeof line,
                "  %-16s %-10s generation %.1f ms, TF change %.4f ms, refine %.1f ms, %.2f MiB, "
                "%zu nodes",
                d.name.c_str(), to_string(k).c_str(), s.generation_ms, s.tf_change_ms, s.refine_ms,
                double(s.bytes) / (1 << 20), s.nodes);
            log(line);
        }
        for (size_t r = 0; r < out.rows.size(); ++r) {
            RowResult& row = out.rows[r];
            CellResult c = run_cell(k, session, row_frames(o, row.mode, session, k), &reference[r]);
            const CellResult& none = row.cells[0];
            c.speedup = c.frame_ms.mean > 0 ? none.frame_ms.mean / c.frame_ms.mean : 0;
            c.sample_reduction = c.samples ? double(none.samples) / double(c.samples) : 0;
            row.cells.push_back(c);
            log_cell(log, out, row, c);
            if (!c.exact && log)
                log("  !!! " + d.name + " " + to_string(row.mode) + " " + to_string(k) +
                    ": view 0 differs from none: an exactness bug");
        }
        session.drop_structures();
    }
    return out;
}

}  // namespace

std::string to_string(RowMode m) {
    switch (m) {
        case RowMode::MarchingOnly:
            return "Marching only";
        case RowMode::EarlyExit:
            return "+ Early exit";
        case RowMode::Shading:
            return "+ Shading";
        case RowMode::Lighting:
            return "+ Lighting";
    }
    return "?";
}

std::string csv_name(RowMode m) {
    switch (m) {
        case RowMode::MarchingOnly:
            return "marching_only";
        case RowMode::EarlyExit:
            return "early_exit";
        case RowMode::Shading:
            return "shading";
        case RowMode::Lighting:
            return "lighting";
    }
    return "?";
}

RowMode parse_row_mode(const std::string& name) {
    if (name == "marching") return RowMode::MarchingOnly;
    if (name == "early-exit") return RowMode::EarlyExit;
    if (name == "shading") return RowMode::Shading;
    if (name == "lighting") return RowMode::Lighting;
    throw Error("--rows", "row",
                "unknown '" + name + "'; expected one of: marching, early-exit, shading, lighting");
}

RenderOptions row_render_options(const FaludiOptions& o, RowMode m, const Box3f& bounds) {
    RenderOptions ro;
    ro.step = o.step;
    ro.interpolation = o.interpolation;
    ro.ert = m == RowMode::MarchingOnly ? kNoEarlyTermination : o.ert;
    ro.threads = o.threads;
    if (m == RowMode::Shading || m == RowMode::Lighting) {
        // The paper's model (Section 4.4): Disney diffuse, GGX, Smith joint GGX, Schlick.
        ro.features.shading = ShadingModel::Pbr;
    }
    if (m == RowMode::Lighting) {
        // One spotlight above, in front and to the left of the volume, aimed at its centre,
        // with shadow rays from every shaded sample through the structure.
        const Vec3f c = bounds.center(), e = bounds.extent();
        ro.features.light.kind = LightKind::Spot;
        ro.features.light.position = c + Vec3f{-0.8f * e.x, 1.2f * e.y, 1.0f * e.z};
        ro.features.light.target = c;
        ro.features.light.cone_deg = 40.f;
        ro.features.shadows.enabled = true;
        ro.features.shadows.step = o.shadow_step;
    }
    return ro;
}

std::string to_string(TargetStatus s) {
    switch (s) {
        case TargetStatus::Met:
            return "met";
        case TargetStatus::Missed:
            return "MISSED";
        case TargetStatus::NotMeasured:
            return "not measured";
        case TargetStatus::Info:
            return "info";
    }
    return "?";
}

const CellResult* RowResult::find(AccelKind k) const {
    for (const CellResult& c : cells)
        if (c.kind == k) return &c;
    return nullptr;
}

double RowResult::ideal_speedup() const {
    const CellResult* none = find(AccelKind::None);
    if (!none || ideal_samples == 0) return 0;
    return double(none->samples) / double(ideal_samples);
}

double RowResult::share_of_ideal(AccelKind k) const {
    const CellResult* c = find(k);
    const double ideal = ideal_speedup();
    return c && ideal > 0 ? c->speedup / ideal : 0;
}

const StructureResult* DatasetResult::find(AccelKind k) const {
    for (const StructureResult& s : structures)
        if (s.kind == k) return &s;
    return nullptr;
}

std::vector<std::string> FaludiReport::exactness_failures() const {
    std::vector<std::string> out;
    for (const DatasetResult& d : datasets)
        for (const RowResult& r : d.rows)
            for (const CellResult& c : r.cells)
                if (!c.exact)
                    out.push_back(d.name + " / " + to_string(r.mode) + " / " + to_string(c.kind));
    return out;
}

std::vector<AccelKind> bench_columns(const std::vector<AccelKind>& accels) {
    std::vector<AccelKind> out{AccelKind::None};
    for (AccelKind k : accels)
        if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
    return out;
}

FaludiReport run_faludi(const std::vector<BenchDataset>& datasets, const FaludiOptions& options,
                        const LogFn& log, const PartialFn& partial) {
    if (options.modes.empty())
        throw Error("bench faludi", "rows", "expected at least one row mode");
    FaludiReport report;
    report.options = options;
    for (const BenchDataset& d : datasets) {
        if (log) log("dataset " + d.name + ": " + d.description);
        report.datasets.push_back(run_dataset(d, options, log));
        if (partial) partial(report);
    }
    return report;
}

// ---- targets ----------------------------------------------------------------------------------

namespace {

bool is_large(const DatasetResult& d) {
    return d.dims.x >= 512 && d.dims.y >= 512 && d.dims.z >= 512;
}

std::string row_label(const DatasetResult& d, const RowResult& r) {
    return d.name + " " + csv_name(r.mode);
}

// Worst row of f (lower is worse when `higher_is_better`), over the rows where f is defined.
struct Worst {
    bool any = false;
    double value = 0;
    std::string where;
    void add(double v, const std::string& w, bool higher_is_better) {
        if (!any || (higher_is_better ? v < value : v > value)) value = v, where = w;
        any = true;
    }
};

TargetCheck verdict(std::string target, const Worst& w, double threshold, bool higher_is_better,
                    const char* unit, const std::string& extra = {}) {
    TargetCheck t;
    t.target = std::move(target);
    if (!w.any) {
        t.status = TargetStatus::NotMeasured;
        t.measured = "no row to measure" + extra;
        return t;
    }
    const bool ok = higher_is_better ? w.value >= threshold : w.value <= threshold;
    t.status = ok ? TargetStatus::Met : TargetStatus::Missed;
    t.measured = "worst " + fmt(unit, w.value) + " (" + w.where + ")" + extra;
    return t;
}

}  // namespace

std::vector<TargetCheck> check_targets(const FaludiReport& rep) {
    std::vector<TargetCheck> out;
    Worst share, own_share, tree, vs_distance, vs_minmax, vs_interval, gen, tf;
    double ratio_lo = 1e300, ratio_hi = 0;
    for (const DatasetResult& d : rep.datasets) {
        for (const RowResult& r : d.rows) {
            // Issue 13's measure, on every row: the default structure's time speedup over its
            // own sample reduction (how much of the samples it removes it turns into time).
            if (const CellResult* c = r.find(default_accel()); c && c->sample_reduction > 0)
                own_share.add(100 * c->speedup / c->sample_reduction, row_label(d, r), true);
            const CellResult* bf = r.find(AccelKind::Bitfield);
            if (!bf) continue;
            // The targets are about skipping: the marching and early-exit rows.
            if (r.mode == RowMode::Shading || r.mode == RowMode::Lighting) continue;
            if (r.ideal_speedup() > 0)
                share.add(100 * r.share_of_ideal(AccelKind::Bitfield), row_label(d, r), true);
            if (is_large(d)) tree.add(bf->speedup, row_label(d, r), true);
            double best_distance = 0;
            for (AccelKind k : {AccelKind::Distance, AccelKind::Chebyshev})
                if (const CellResult* c = r.find(k))
                    if (best_distance == 0 || c->frame_ms.mean < best_distance)
                        best_distance = c->frame_ms.mean;
            if (best_distance > 0)
                vs_distance.add(bf->frame_ms.mean / best_distance, row_label(d, r), false);
            if (d.tf_name == "mr-gap")
                if (const CellResult* mm = r.find(AccelKind::MinMax))
                    vs_minmax.add(mm->frame_ms.mean / bf->frame_ms.mean, row_label(d, r), true);
            if (d.tf_name == "mr-gap")
                if (const CellResult* mi = r.find(AccelKind::MinMaxInterval))
                    vs_interval.add(mi->frame_ms.mean / bf->frame_ms.mean, row_label(d, r), true);
        }
        if (const StructureResult* b = d.find(AccelKind::Bitfield)) {
            if (is_large(d) && d.type == VoxelType::UInt8) gen.add(b->generation_ms, d.name, false);
            tf.add(b->tf_change_ms, d.name, false);
            for (AccelKind k : {AccelKind::Distance, AccelKind::Chebyshev})
                if (const StructureResult* s = d.find(k); s && b->tf_change_ms > 0) {
                    ratio_lo = std::min(ratio_lo, s->tf_change_ms / b->tf_change_ms);
                    ratio_hi = std::max(ratio_hi, s->tf_change_ms / b->tf_change_ms);
                }
        }
    }
    out.push_back(verdict("the default structure (" + to_string(default_accel()) +
                              ")'s time speedup >= 70% of its sample reduction on every row",
                          own_share, 70, true, "%.0f%%"));
    out.push_back(verdict("bitfield reaches >= 70% of the ideal speedup on every row", share, 70,
                          true, "%.0f%%"));
    out.push_back(verdict("bitfield >= 5x over none on the >= 512^3 sparse tree-like volume", tree,
                          5, true, "%.2fx"));
    out.push_back(verdict("bitfield frame time within 1.3x of the faster distance map on every row",
                          vs_distance, 1.3, false, "%.2fx"));
    out.push_back(verdict("bitfield >= 1.5x faster than minmax on the mr-gap rows", vs_minmax, 1.5,
                          true, "%.2fx"));
    out.push_back(verdict("bitfield octree generation for a 512^3 uint8 volume <= 150 ms", gen, 150,
                          false, "%.1f ms"));
    out.push_back(verdict("bitfield TF change <= 0.1 ms", tf, 0.1, false, "%.4f ms"));
    TargetCheck ratio;
    ratio.target =
        "distance maps' rebuild time on a TF change, as a multiple of bitfield's TF change";
    ratio.status = ratio_hi > 0 ? TargetStatus::Info : TargetStatus::NotMeasured;
    ratio.measured = ratio_hi > 0 ? fmt("%.0f", ratio_lo) + "x .. " + fmt("%.0f", ratio_hi) + "x"
                                  : "no distance map and bitfield pair";
    out.push_back(ratio);
    {
        // Not a target of the issue: the same comparison against the paper's own min-max test.
        TargetCheck t = verdict("bitfield vs minmax-interval (the paper's min-max test) on mr-gap",
                                vs_interval, 1.5, true, "%.2fx");
        if (t.status != TargetStatus::NotMeasured) t.status = TargetStatus::Info;
        out.push_back(t);
    }
    return out;
}

}  // namespace lacuna::bench
