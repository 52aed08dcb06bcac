// `lacuna info`: what a volume file holds — dims, type, spacing, orientation, value range and a
// histogram summary.
#include <algorithm>
#include <cstdio>
#include <vector>

#include "cli_common.h"
#include "lacuna/orientation.h"
#include "lacuna/rgb.h"

namespace lacuna::cli {

namespace {

void run(const VolumeArgs& args) {
    Progress summary("info", 0, "");
    const Volume v = load_volume(args);
    const Vec3i d = v.dims();
    std::printf("file:        %s\n", args.path.c_str());
    std::printf("dims:        %d x %d x %d (%zu voxels, %.1f MiB)\n", d.x, d.y, d.z,
                v.voxel_count(), double(v.bytes()) / (1 << 20));
    std::printf("type:        %s\n", to_string(v.type()).c_str());
    if (const RgbColours* rgb = rgb_colours(v))
        std::printf(
            "channels:    %s (colour from the data; opacity scalar: %s, %s)\n",
            rgb->channels == 4 ? "RGBA (RGBA32)" : "RGB (RGB24)", to_string(rgb->opacity).c_str(),
            rgb->opacity == RgbOpacity::Luminance ? "Rec. 709 float32" : "the channel, uint8");
    std::printf("spacing:     %g x %g x %g mm\n", v.spacing.x, v.spacing.y, v.spacing.z);
    // World frame (docs/formats.md): patient RAS mm; origin and direction also in ITK's LPS.
    const Affine a = index_to_world(v);
    const Box3f wb = world_bounds(v);
    std::printf("orientation: %s (the RAS direction +i, +j, +k point toward)\n",
                orientation_code(v).c_str());
    std::printf("geometry:    %s\n", v.geometry_source.empty()
                                         ? "none in the file: world = index x spacing"
                                         : v.geometry_source.c_str());
    std::printf("affine:      RAS mm = [%g %g %g %g] [%g %g %g %g] [%g %g %g %g] * (i, j, k, 1)\n",
                a.m[0][0], a.m[0][1], a.m[0][2], a.t[0], a.m[1][0], a.m[1][1], a.m[1][2], a.t[1],
                a.m[2][0], a.m[2][1], a.m[2][2], a.t[2]);
    std::printf("RAS bounds:  x %g .. %g, y %g .. %g, z %g .. %g mm\n", wb.lo.x, wb.hi.x, wb.lo.y,
                wb.hi.y, wb.lo.z, wb.hi.z);
    std::printf("origin:      %g, %g, %g (LPS)\n", v.origin.x, v.origin.y, v.origin.z);
    std::printf("direction:   [%g %g %g] [%g %g %g] [%g %g %g] (LPS, row-major)\n", v.direction[0],
                v.direction[1], v.direction[2], v.direction[3], v.direction[4], v.direction[5],
                v.direction[6], v.direction[7], v.direction[8]);
    const ValueRange r = v.data_range(), vr = v.vis_range();
    std::printf("value range: %g .. %g\n", r.min, r.max);
    std::printf("vis range:   %g .. %g\n", vr.min, vr.max);
    if (v.nan_voxels)
        std::printf("NaN voxels:  %zu (%.2f%%), read as the minimum %g (background)\n",
                    v.nan_voxels, 100.0 * double(v.nan_voxels) / double(v.voxel_count()), r.min);

    // 16-bin histogram over the data range, plus the share of voxels at the minimum (background).
    // In double, as the viewer's histogram: voxels are finite (Volume::compute_range) and the
    // width of two floats always fits a double, so u is finite and the clamp gives a bin for
    // every voxel, however narrow (scl_slope 1e-40) or wide (+-3e38) the data.
    constexpr int kBins = 16;
    std::vector<uint64_t> hist(kBins, 0);
    uint64_t at_min = 0;
    const double width = double(r.max) - double(r.min);
    const double scale = width > 0 ? double(kBins) / width : 0.0;
    visit_voxels(v, [&](const auto* p) {
        const size_t n = v.voxel_count();
        for (size_t i = 0; i < n; ++i) {
            const float x = float(p[i]);
            at_min += x == r.min;
            const double u = (double(x) - double(r.min)) * scale;
            hist[size_t(u < 0 ? 0 : (u >= kBins ? kBins - 1 : int(u)))]++;
        }
    });
    const double n = double(v.voxel_count());
    std::printf("at minimum:  %.1f%% of voxels\n", 100.0 * double(at_min) / n);
    std::printf("histogram:   (%d bins over the value range, %% of voxels)\n", kBins);
    const uint64_t peak = *std::max_element(hist.begin(), hist.end());
    for (int b = 0; b < kBins; ++b) {
        const double lo = double(r.min) + width * double(b) / kBins;
        const int bar = peak ? int(40.0 * double(hist[b]) / double(peak) + 0.5) : 0;
        std::printf("  %10.4g  %5.1f%%  %s\n", lo, 100.0 * double(hist[b]) / n,
                    std::string(size_t(bar), '#').c_str());
    }
    std::fflush(stdout);
    summary.done();
}

}  // namespace

void register_info(CLI::App& app) {
    auto a = std::make_shared<VolumeArgs>();
    auto* cmd = app.add_subcommand("info", "Describe a volume file");
    add_volume_args(*cmd, *a);
    cmd->callback([a] { run(*a); });
}

}  // namespace lacuna::cli
