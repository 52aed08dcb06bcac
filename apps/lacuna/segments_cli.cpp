#include "segments_cli.h"

#include <cstdio>

#include "core/parallel.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/segments.h"
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
    SegmentOptions so;
    so.mode = parse_segment_mode(a.mode.empty() ? "mask" : a.mode);
    so.tint = a.tint;
    so.leaf_cells = f.leaf;
    so.bitfield_bits = f.bits;
    // bitfield: the label bitfield octree (labels + intensity bins); any other structure skips on
    // the intensity alone (mask mode).
    const AccelKind kind = parse_accel(f.accel);
    so.skip = kind == AccelKind::Bitfield;
    const bool masked = so.mode == SegmentMode::Masked;
    if (!masked && kind != AccelKind::None && kind != AccelKind::Bitfield)
        throw Error("--accel", "structure",
                    "the label volume alone takes 'none' or 'bitfield' (the label bitfield "
                    "octree), got '" + f.accel + "'");
    if (masked && a.labels.empty())
        throw Error("--segments", "mode", "mask mode needs --labels FILE");
    if (masked && f.tf.empty()) throw Error("render", "--tf", "mask mode needs a transfer function");
    std::optional<TransferFunction> tf;
    if (masked) tf = resolve_transfer_function(f.tf);
    const Volume vol = load_volume(f.volume);
    Volume label_store;
    if (!a.labels.empty()) {
        VolumeArgs la;
        la.path = a.labels;
        label_store = load_volume(la);
    }
    const Volume& labels = a.labels.empty() ? vol : label_store;
    LabelTable table = a.style.empty() ? default_label_table(labels)
                                       : load_label_table(a.style, labels);
    for (const std::string& s : a.show) set_label_visibility(table, s, true, "--show");
    for (const std::string& s : a.hide) set_label_visibility(table, s, false, "--hide");
    Progress progress("building label octree");
    SegmentRenderer seg(masked ? &vol : nullptr, labels, so);
    progress.done();
    std::unique_ptr<Accel> accel;
    if (masked) {
        const TransferLut lut = discretise(*tf, vol.vis_range());
        seg.set_transfer_function(lut);
        if (!so.skip && kind != AccelKind::None) {
            AccelOptions ao;
            ao.leaf_cells = f.leaf;
            ao.bitfield_bits = f.bits;
            ao.threads = f.ro.threads;
            accel = make_accel(kind, vol, ao);
            accel->set_transfer_function(lut);
            seg.set_accel(accel.get());
        }
    }
    seg.set_labels(table);
    const Camera cam = Camera::orbit(seg.bounds(), f.op, f.w, f.h);
    const RenderResult r = seg.render(cam, f.ro);
    write_png(f.out, r.image);
    if (!f.heatmap.empty()) write_png(f.heatmap, heatmap(r.sample_counts, f.w, f.h));
    int shown = 0;
    for (const auto& s : table.styles) shown += s.visible && s.opacity > 0.f;
    std::printf("%s: %dx%d, segments %s, %d of %d labels visible, accel %s, %d threads\n",
                f.volume.path.c_str(), f.w, f.h, to_string(so.mode).c_str(), shown,
                table.size(), so.skip ? "label bitfield octree" : f.accel.c_str(),
                resolve_threads(f.ro.threads));
    if (so.skip)
        std::printf("label octree: build %.1f ms, %d bits per node, %.2f MiB, label change %.3f ms\n",
                    seg.stats().build_seconds * 1e3, 64 * seg.stats().label_words,
                    double(seg.stats().bytes) / (1 << 20), seg.stats().label_update_seconds * 1e3);
    std::printf("render time %.1f ms, %.1f samples/ray\n", r.stats.seconds * 1e3,
                r.stats.samples_per_ray());
    std::printf("wrote %s\n", f.out.c_str());
}

}  // namespace lacuna::cli
