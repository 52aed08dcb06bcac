#include "segments_cli.h"

#include <cstdio>

#include "core/parallel.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/segments.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"

namespace lacuna::cli {

void add_segment_args(CLI::App& cmd, SegmentArgs& a) {
    cmd.add_option("--labels", a.labels,
                   "Label volume (same dims) masking the intensity volume: segment visibility");
    cmd.add_option("--segments", a.mode,
                   "Segment mode: 'mask' (intensity through --tf, masked by --labels) or "
                   "'labels' (the label volume alone: the VOLUME argument, or --labels)");
    cmd.add_option("--label-style", a.style,
                   "Per-label colour/opacity/visibility: a .json label table or an MRIcron .lut");
    cmd.add_option("--show", a.show, "Labels to show: all, none or a list like 1,2,37-40")
        ->take_all();
    cmd.add_option("--hide", a.hide, "Labels to hide (after --show): all, none or a list")
        ->take_all();
    cmd.add_option("--label-tint", a.tint,
                   "Mask mode: weight of the label colour against the TF colour (0..1)")
        ->capture_default_str();
}

void render_segments(const SegmentArgs& a, const SegmentFrame& f) {
    FrameSpec spec = f.spec;
    const bool masked = spec.segments.mode == SegmentMode::Masked;
    const bool octree = std::holds_alternative<structure::LabelOctree>(spec.structure);
    if (masked && a.labels.empty())
        throw Error("--segments", "mode", "mask mode needs --labels FILE");
    if (masked && f.tf.empty() && !f.tf_value)
        throw Error("render", "--tf", "mask mode needs a transfer function");
    std::optional<TransferFunction> tf;
    if (masked) tf = f.tf_value ? *f.tf_value : resolve_transfer_function(f.tf);
    // Labels mode reads the label volume alone: --labels, or else the VOLUME argument.
    VolumeArgs la;
    la.path = a.labels;
    Session session(load_volume(masked || a.labels.empty() ? f.volume : la), f.threads);
    if (masked) {
        session.set_labels(load_volume(la));
        session.set_transfer_function(*tf);
    }
    // A session file's frame carries its table; otherwise the default or --label-style's.
    LabelTable table = spec.segments.labels ? *spec.segments.labels
                       : a.style.empty()    ? session.label_table()
                                            : load_label_table(a.style, session.label_volume());
    for (const std::string& s : a.show) set_label_visibility(table, s, true, "--show");
    for (const std::string& s : a.hide) set_label_visibility(table, s, false, "--hide");
    spec.segments.labels = table;
    Progress progress("building label octree");
    session.prepare(spec);
    progress.done();
    const FrameResult r = session.render(spec);
    write_png(f.out, r.image);
    if (!f.heatmap.empty()) write_png(f.heatmap, heatmap(r.sample_counts, spec.width, spec.height));
    int shown = 0;
    for (const auto& s : table.styles) shown += s.visible && s.opacity > 0.f;
    std::printf("%s: %dx%d, segments %s, %d of %d labels visible, accel %s, %d threads\n",
                f.volume.path.c_str(), spec.width, spec.height,
                to_string(spec.segments.mode).c_str(), shown, table.size(),
                octree ? "label bitfield octree" : f.accel.c_str(), resolve_threads(f.threads));
    if (octree)
        std::printf(
            "label octree: build %.1f ms, %d bits per node, %.2f MiB, label change %.3f ms\n",
            r.segments->build_seconds * 1e3, 64 * r.segments->label_words,
            double(r.segments->bytes) / (1 << 20), r.segments->label_update_seconds * 1e3);
    std::printf("render time %.1f ms, %.1f samples/ray\n", r.stats.seconds * 1e3,
                r.stats.samples_per_ray());
    std::printf("wrote %s\n", f.out.c_str());
}

}  // namespace lacuna::cli
