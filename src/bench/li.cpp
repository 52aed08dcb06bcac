#include "bench/li.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>

#include "bench/stats.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/session.h"
#include "slice/growing_boxes_source.h"

namespace lacuna::bench {

namespace {

double fps(const LiColumn* c) {
    return c && c->mean_ms > 0 ? 1e3 / c->mean_ms : 0;
}
double ratio(const LiColumn* a, const LiColumn* b) {
    return a && b && b->mean_ms > 0 ? a->mean_ms / b->mean_ms : 0;
}
double cpu_ratio(const LiColumn* a, const LiColumn* b) {
    return a && b && b->cpu_ms > 0 ? a->cpu_ms / b->cpu_ms : 0;
}
double cpu_now_ms() {
    return 1e3 * double(std::clock()) / CLOCKS_PER_SEC;
}

void finish(LiColumn& c) {
    c.mean_ms = mean(c.frame_ms);
    const double n = double(std::max<size_t>(c.frame_ms.size(), 1));
    c.cpu_ms /= n;
    c.setup_fraction /= n;
    c.setup_wall /= n;
    c.culled /= n;
    c.clipped /= n;
    c.samples /= n;
}

}  // namespace

const LiColumn* LiDataset::find(const std::string& n) const {
    for (const LiColumn& c : columns)
        if (c.name == n) return &c;
    return nullptr;
}

LiReport run_li(const std::vector<BenchDataset>& datasets, const LiOptions& o, const LiLog& log) {
    LiReport rep;
    rep.options = o;
    for (const BenchDataset& ds : datasets) {
        const Volume& vol = *ds.volume;
        LiDataset d;
        d.name = ds.name;
        d.description = ds.description;
        d.tf_name = ds.tf_name;
        d.dims = vol.dims();
        // Every column renders through one session: the ESS box source is built (and timed) by
        // its first frame's prepare(), kept for the other columns, and the structures of the
        // ray-marcher columns next to it.
        Session session(vol, o.threads);  // shares the voxels
        session.set_transfer_function(ds.tf);
        FrameSpec base;
        base.renderer = Renderer::Slicer;
        base.structure = structure::None{};
        base.sampling.step = o.step;
        base.sampling.early_termination.reset();  // no per-pixel termination: the paper's GPU
                                                  // has none
        base.slicer.occlusion_threshold = o.threshold;
        base.slicer.occlusion_map = o.map_size;
        base.slicer.occlusion_updates = o.initial_updates;
        const std::vector<FrameSpec> basic = orbit_frames(base, o.orbit);
        // The ESS box source, by the name the slicer takes.
        structure::GrowingBoxes gb;
        gb.coalesce = o.boxes.coalesce;
        gb.coalesce_edge = o.boxes.coalesce_edge;
        FrameSpec ess = basic[0];
        ess.structure = parse_structure(o.ess, Renderer::Slicer, o.accel, gb);
        const FrameResult built = session.prepare(ess);  // validates: the slicer takes it
        d.source_ms = (built.build_seconds + built.tf_sync_seconds) * 1e3;
        const BoxSource* source = session.built_box_source(ess);
        if (const auto* src = dynamic_cast<const GrowingBoxesSource*>(source)) {
            const BoxesBuildStats& bs = src->stats();
            d.partition_ms = 1e3 * (bs.gradient + bs.grow + bs.measure + bs.ranges);
            d.bsp_ms = 1e3 * (bs.split + bs.merge);
        }
        if (log)
            log(ds.name + ": " + o.ess + " boxes built in " + fmt("%.1f", d.source_ms) + " ms");

        // The orbit with the ESS boxes (or Basic's one box) and the occlusion settings.
        auto frames = [&](bool boxes, bool occlusion, OcclusionUse use, bool adaptive) {
            std::vector<FrameSpec> fs = basic;
            for (FrameSpec& f : fs) {
                if (boxes) f.structure = ess.structure;
                f.slicer.occlusion = occlusion;
                f.slicer.occlusion_use = use;
                f.slicer.adaptive_updates = adaptive;
            }
            return fs;
        };
        Image basic0, ess0, map0, cc0;
        auto run = [&](const std::string& name, const std::vector<FrameSpec>& fs, Image* first) {
            LiColumn col;
            col.name = name;
            for (size_t v = 0; v < fs.size(); ++v) {
                const double cpu0 = cpu_now_ms();
                FrameResult r = session.render(fs[v]);
                col.cpu_ms += cpu_now_ms() - cpu0;
                const SlicerFrameStats& st = *r.slicer;
                col.frame_ms.push_back(r.stats.seconds * 1e3);
                col.setup_fraction += st.setup_cpu_fraction;
                col.setup_wall += st.setup_fraction;
                col.culled += st.culled_fraction;
                col.clipped += st.clipped_fraction;
                col.samples += double(r.stats.samples);
                if (v == 0 && first) *first = std::move(r.image);
                const bool boxes = !std::holds_alternative<structure::None>(fs[v].structure);
                if (v == 0 && boxes) d.boxes = st.boxes;
                if (v == 0 && boxes)
                    d.box_voxels =
                        st.voxels / (double(d.dims.x - 1) * (d.dims.y - 1) * (d.dims.z - 1));
                if (name == "ESS+CC") {
                    d.desired_updates.push_back(st.desired_updates);
                    d.actual_updates.push_back(st.map_updates);
                }
            }
            finish(col);
            if (log) log("  " + name + ": " + fmt("%.1f", col.mean_ms) + " ms/frame");
            d.columns.push_back(std::move(col));
        };
        using U = OcclusionUse;
        run("Basic", frames(false, false, U::CullClip, false), &basic0);
        run("ESS", frames(true, false, U::CullClip, false), &ess0);
        run("ESS+CC", frames(true, true, U::CullClip, true), &cc0);
        run("ESS+M", frames(true, true, U::MapOnly, false), &map0);
        run("ESS+C", frames(true, true, U::CullOnly, true), nullptr);
        d.ess_exact = basic0.rgba == ess0.rgba;
        d.map_only_exact = map0.rgba == ess0.rgba;
        for (size_t i = 0; i < cc0.rgba.size() && i < ess0.rgba.size(); ++i)
            d.max_cc_diff = std::max(d.max_cc_diff, std::abs(int(cc0.rgba[i]) - int(ess0.rgba[i])));

        if (o.march) {
            std::vector<std::pair<std::string, Structure>> marched;
            marched.push_back({"march none", structure::None{}});
            if (o.ess == "kdtree")
                marched.push_back({"march kdtree", structure_of(AccelKind::KdTree, o.accel)});
            for (const auto& [name, st] : marched) {
                std::vector<FrameSpec> fs = basic;
                for (FrameSpec& f : fs) {
                    f.renderer = Renderer::RayMarcher;
                    f.structure = st;
                }
                session.prepare(fs[0]);  // the kd-tree's build, outside the frame times
                LiColumn col;
                col.name = name;
                const double cpu0 = cpu_now_ms();
                const OrbitRun run_m = run_orbit(session, fs);
                col.cpu_ms = cpu_now_ms() - cpu0;
                for (double s : run_m.frame_seconds) col.frame_ms.push_back(s * 1e3);
                col.samples = double(run_m.samples);
                finish(col);
                col.samples = double(run_m.samples) / double(std::max<size_t>(fs.size(), 1));
                if (log) log("  " + name + ": " + fmt("%.1f", col.mean_ms) + " ms/frame");
                d.columns.push_back(std::move(col));
            }
        }
        // Figure 6: a longer orbit of ESS+CC with the adaptive controller, first dataset only.
        // The controller starts afresh: the frame before was another column's (ESS+C's culling
        // only, or the ray marcher's).
        if (o.updates_views > 0 && rep.datasets.empty()) {
            OrbitSpec spec = o.orbit;
            spec.views = o.updates_views;
            std::vector<FrameSpec> long_orbit = orbit_frames(base, spec);
            for (FrameSpec& f : long_orbit) {
                f.structure = ess.structure;
                f.slicer.occlusion = true;
                f.slicer.occlusion_use = OcclusionUse::CullClip;
                f.slicer.adaptive_updates = true;
            }
            rep.figure6.dataset = ds.name;
            for (const FrameSpec& f : long_orbit) {
                const FrameResult r = session.render(f);
                rep.figure6.desired.push_back(r.slicer->desired_updates);
                rep.figure6.actual.push_back(r.slicer->map_updates);
                rep.figure6.skipped.push_back(r.slicer->skipped_fraction);
            }
            if (log) log("  Figure 6: " + std::to_string(long_orbit.size()) + " ESS+CC frames");
        }
        rep.datasets.push_back(std::move(d));
    }
    return rep;
}

std::string li_markdown(const LiReport& r, const RunInfo& info) {
    const LiOptions& o = r.options;
    std::string out =
        "# lacuna bench li: Tables 1 and 2 of Li, Mueller & Kaufman (2003) on our data\n\n";
    out += run_info_markdown(info);
    out += "- Settings: " + std::to_string(o.orbit.size) + "×" + std::to_string(o.orbit.size) +
           " pixels, " + std::to_string(o.orbit.views) + " views (azimuth 360°·i/" +
           std::to_string(o.orbit.views) + ", elevation " + fmt("%g", o.orbit.elevation_deg) +
           "°, perspective), slice distance " + fmt("%g", o.step) +
           " voxel, no early termination (as the paper's GPU), ESS box source `" + o.ess +
           "`, occlusion threshold " + fmt("%g", o.threshold) + ", map " +
           std::to_string(o.map_size) +
           "², adaptive updates from k = " + std::to_string(o.initial_updates) +
           " (ESS+CC, ESS+C; ESS+M uses k fixed), threads " +
           (o.threads > 0 ? std::to_string(o.threads) : "all") + ".\n\n";

    out += "## Table 1: empty space skipping (frames per second)\n\n";
    out +=
        "| dataset | size | boxes | Basic | ESS | speedup | polygon set-up (ESS), CPU / wall | ESS "
        "== Basic |\n";
    out += "|---|---|---:|---:|---:|---:|---:|---|\n";
    double sum_ess = 0;
    for (const LiDataset& d : r.datasets) {
        const LiColumn *b = d.find("Basic"), *e = d.find("ESS");
        const double s = ratio(b, e);
        sum_ess += s;
        out += "| " + d.name + " | " + std::to_string(d.dims.x) + "×" + std::to_string(d.dims.y) +
               "×" + std::to_string(d.dims.z) + " | " + std::to_string(d.boxes) + " | " +
               fmt("%.2f", fps(b)) + " | " + fmt("%.2f", fps(e)) + " | " + fmt("%.2f", s) + " | " +
               fmt("%.1f%%", 100 * (e ? e->setup_fraction : 0)) + " / " +
               fmt("%.1f%%", 100 * (e ? e->setup_wall : 0)) + " | " +
               (d.ess_exact ? "yes" : "**NO**") + " |\n";
    }
    if (!r.datasets.empty())
        out +=
            "| average | | | | | " + fmt("%.2f", sum_ess / double(r.datasets.size())) + " | | |\n";

    out += "\n## Table 2: occlusion clipping\n\n";
    out +=
        "| dataset | Basic | ESS | ESS+CC | ESS+M | ESS+C | culled % | clipped % | total % | "
        "speedup ESS | CC | ESS+CC |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    double a_cul = 0, a_clip = 0, a_ess = 0, a_cc = 0, a_both = 0;
    for (const LiDataset& d : r.datasets) {
        const LiColumn *b = d.find("Basic"), *e = d.find("ESS"), *cc = d.find("ESS+CC"),
                       *m = d.find("ESS+M"), *c = d.find("ESS+C");
        const double s_ess = ratio(b, e), s_cc = ratio(e, cc), s_both = ratio(b, cc);
        a_cul += cc->culled;
        a_clip += cc->clipped;
        a_ess += s_ess;
        a_cc += s_cc;
        a_both += s_both;
        out += "| " + d.name + " | " + fmt("%.2f", fps(b)) + " | " + fmt("%.2f", fps(e)) + " | " +
               fmt("%.2f", fps(cc)) + " | " + fmt("%.2f", fps(m)) + " | " + fmt("%.2f", fps(c)) +
               " | " + fmt("%.1f", 100 * cc->culled) + " | " + fmt("%.1f", 100 * cc->clipped) +
               " | " + fmt("%.1f", 100 * (cc->culled + cc->clipped)) + " | " + fmt("%.2f", s_ess) +
               " | " + fmt("%.2f", s_cc) + " | " + fmt("%.2f", s_both) + " |\n";
    }
    if (!r.datasets.empty()) {
        const double n = double(r.datasets.size());
        out += "| average | | | | | | " + fmt("%.1f", 100 * a_cul / n) + " | " +
               fmt("%.1f", 100 * a_clip / n) + " | " + fmt("%.1f", 100 * (a_cul + a_clip) / n) +
               " | " + fmt("%.2f", a_ess / n) + " | " + fmt("%.2f", a_cc / n) + " | " +
               fmt("%.2f", a_both / n) + " |\n";
    }
    out +=
        "\nFrames per second = 1000 / mean frame time over the orbit. Culled / clipped = share "
        "of the non-empty voxels (cells in the ESS boxes) skipped, mean over the orbit "
        "(ESS+CC). Speedups: ESS = Basic/ESS, CC = ESS/(ESS+CC), ESS+CC = Basic/(ESS+CC), "
        "all from this run.\n\n";

    out += "## CPU time per frame (all threads) and the speedups it gives\n\n";
    out +=
        "Wall-clock frame rates above depend on what else the machine runs; process CPU time "
        "per frame counts only this run's work.\n\n";
    out +=
        "| dataset | Basic | ESS | ESS+CC | ESS+M | ESS+C | march none | speedup ESS | CC | "
        "ESS+CC | slicer Basic / march none |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const LiDataset& d : r.datasets) {
        const LiColumn *b = d.find("Basic"), *e = d.find("ESS"), *cc = d.find("ESS+CC"),
                       *m = d.find("ESS+M"), *c = d.find("ESS+C"), *mn = d.find("march none");
        auto cpu = [](const LiColumn* x) { return x ? fmt("%.0f", x->cpu_ms) : std::string("–"); };
        out += "| " + d.name + " | " + cpu(b) + " | " + cpu(e) + " | " + cpu(cc) + " | " + cpu(m) +
               " | " + cpu(c) + " | " + cpu(mn) + " | " + fmt("%.2f", cpu_ratio(b, e)) + " | " +
               fmt("%.2f", cpu_ratio(e, cc)) + " | " + fmt("%.2f", cpu_ratio(b, cc)) + " | " +
               fmt("%.2f", cpu_ratio(b, mn)) + " |\n";
    }
    out += "\n(ms of CPU per frame.)\n\n";
    out += "## Details\n\n";
    out +=
        "| dataset | TF | source build [ms] (partition + BSP) | box voxels % | Basic [ms] | ESS "
        "[ms] | ESS+CC [ms] | "
        "ESS+M [ms] | ESS+C [ms] | march none [ms] | march ESS [ms] | ESS+M == ESS | max "
        "|ESS+CC − ESS| (8 bit) | map updates desired/actual (mean) |\n";
    out += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|\n";
    for (const LiDataset& d : r.datasets) {
        auto ms = [&](const char* n) {
            const LiColumn* c = d.find(n);
            return c ? fmt("%.1f", c->mean_ms) : std::string("–");
        };
        double des = 0, act = 0;
        for (size_t i = 0; i < d.desired_updates.size(); ++i) {
            des += d.desired_updates[i];
            act += d.actual_updates[i];
        }
        const double n = double(std::max<size_t>(d.desired_updates.size(), 1));
        const std::string parts = d.partition_ms >= 0 ? " (" + fmt("%.1f", d.partition_ms) + " + " +
                                                            fmt("%.1f", d.bsp_ms) + ")"
                                                      : "";
        out += "| " + d.name + " | " + d.tf_name + " | " + fmt("%.1f", d.source_ms) + parts +
               " | " + fmt("%.1f", 100 * d.box_voxels) + " | " + ms("Basic") + " | " + ms("ESS") +
               " | " + ms("ESS+CC") + " | " + ms("ESS+M") + " | " + ms("ESS+C") + " | " +
               ms("march none") + " | " + ms(("march " + o.ess).c_str()) + " | " +
               (d.map_only_exact ? "yes" : "**NO**") + " | " + std::to_string(d.max_cc_diff) +
               " | " + fmt("%.1f", des / n) + " / " + fmt("%.1f", act / n) + " |\n";
    }
    out += "\nThe bound for ESS+CC at threshold T is 1 − T of full scale per channel (" +
           fmt("%.1f", 255.0 * (1.0 - o.threshold)) + " levels, plus rounding).\n";
    return out;
}

std::string li_csv(const LiReport& r) {
    std::string out =
        "dataset,column,mean_ms,cpu_ms,fps,setup_cpu_fraction,culled,clipped,samples_per_frame\n";
    for (const LiDataset& d : r.datasets)
        for (const LiColumn& c : d.columns)
            out += d.name + "," + c.name + "," + fmt("%.3f", c.mean_ms) + "," +
                   fmt("%.3f", c.cpu_ms) + "," + fmt("%.3f", fps(&c)) + "," +
                   fmt("%.4f", c.setup_fraction) + "," + fmt("%.4f", c.culled) + "," +
                   fmt("%.4f", c.clipped) + "," + fmt("%.0f", c.samples) + "\n";
    return out;
}

std::string li_updates_csv(const LiReport& r) {
    std::string out = "dataset,frame,desired_updates,actual_updates,skipped_fraction\n";
    const LiUpdates& u = r.figure6;
    for (size_t i = 0; i < u.desired.size(); ++i)
        out += u.dataset + "," + std::to_string(i) + "," + std::to_string(u.desired[i]) + "," +
               std::to_string(u.actual[i]) + "," + fmt("%.4f", u.skipped[i]) + "\n";
    return out;
}

std::string li_updates_gnuplot(const LiReport& r, const std::string& png) {
    const LiUpdates& u = r.figure6;
    std::string s = "set terminal pngcairo size 900,420 font ',10'\n";
    std::string q = "'";
    for (char c : png) q += c == '\'' ? std::string("''") : std::string(1, c);
    s += "set output " + q + "'\n";
    s += "set title 'Map updates per frame, " + u.dataset + " (ESS+CC, adaptive, " +
         std::to_string(r.options.orbit.size) + "^2, " + std::to_string(u.desired.size()) +
         "-frame orbit)'\n";
    s += "set xlabel 'Frame'\nset ylabel 'Map updates'\nset grid\nset key top right\n"
         "set yrange [0:*]\n";
    s += "$d << EOD\n";
    for (size_t i = 0; i < u.desired.size(); ++i)
        s += std::to_string(i) + " " + std::to_string(u.desired[i]) + " " +
             std::to_string(u.actual[i]) + "\n";
    s += "EOD\n";
    s += "plot $d using 1:2 with steps lw 2 title 'desired (k)', "
         "$d using 1:3 with linespoints pt 7 ps 0.6 title 'actual'\n";
    return s;
}

}  // namespace lacuna::bench
