// Label tables (docs/segments.md): our .json, MRIcron's .lut (768 bytes) with its NAME.txt, and
// the visibility lists ("1,2,37-42") that --hide and the viewer's "hide" take.
//   byte 0 % 3   0: .json, 1: .lut (the first 768 bytes, the rest is the .txt), 2: a list
//   byte 1       the label map's largest value (a 4x2x2 uint16 volume holding 0..that)
// An accepted table has a style for every label, colours and opacities finite in [0,1].
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "lacuna/segments.h"

using namespace lacuna;
using fuzz::fuzz_check;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 2) return 0;
    const int mode = data[0] % 3;
    const int max_label = data[1] + (data[0] >= 128 ? 256 : 0);
    const std::string text(reinterpret_cast<const char*>(data + 2), size - 2);
    Volume labels(Vec3i{4, 2, 2}, VoxelType::UInt16, "labels");
    for (int i = 0; i < 16; ++i)
        labels.data_as<uint16_t>()[i] = uint16_t(i == 15 ? max_label : i % (max_label + 1));
    labels.compute_range("labels");
    return fuzz::guarded([&] {
        LabelTable t;
        if (mode == 0) {
            t = load_label_table(fuzz::scratch_file(text, "table.json"), labels);
        } else if (mode == 1) {
            const std::string lut = text.substr(0, 768);
            fuzz::scratch_file(text.size() > 768 ? text.substr(768) : std::string(), "table.txt");
            t = load_label_table(fuzz::scratch_file(lut, "table.lut"), labels);
        } else {
            t = default_label_table(labels);
            set_label_visibility(t, text, false, "hide");
        }
        fuzz_check(t.size() >= label_count(labels), "a style per label", std::to_string(t.size()));
        for (const LabelStyle& s : t.styles)
            for (float x : {s.r, s.g, s.b, s.opacity})
                fuzz_check(std::isfinite(x) && x >= 0.f && x <= 1.f, "style in [0,1]", s.name);
    });
}
