#include "io/rgb_volume.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "io/io_util.h"
#include "lacuna/error.h"

namespace lacuna {

std::string to_string(RgbOpacity o) {
    switch (o) {
        case RgbOpacity::Luminance:
            return "luminance";
        case RgbOpacity::R:
            return "r";
        case RgbOpacity::G:
            return "g";
        case RgbOpacity::B:
            return "b";
        case RgbOpacity::A:
            return "a";
    }
    return "?";
}

RgbOpacity parse_rgb_opacity(const std::string& name, const std::string& where) {
    static const std::pair<const char*, RgbOpacity> kNames[] = {
        {"luminance", RgbOpacity::Luminance},
        {"r", RgbOpacity::R},
        {"g", RgbOpacity::G},
        {"b", RgbOpacity::B},
        {"a", RgbOpacity::A}};
    for (const auto& [n, o] : kNames)
        if (name == n) return o;
    throw Error(where, "rgb opacity", "expected one of: luminance, r, g, b, a; got '" + name + "'");
}

namespace {

// The colours of the live RGB buffers, by buffer address (lacuna/rgb.h, "Where the colours
// live"). An entry is added when the buffer is made and removed by its owner's destructor
// before the buffer is freed, so an address never names a dead buffer's colours.
struct RgbOwner;
struct Registry {
    std::mutex mutex;
    std::unordered_map<const void*, RgbOwner*> colours;
    std::atomic<size_t> size{0};  // lets scalar volumes skip the lock
};
Registry& registry() {
    static Registry* r = new Registry;  // never destroyed: owners may die after static teardown
    return *r;
}

// Owns an RGB volume's scalar buffer and its colours. A volume whose grid or type is not the
// buffer's (a view of part of it) is not given the colours: they would be read with its strides.
struct RgbOwner {
    void* data = nullptr;
    Vec3i dims{0, 0, 0};
    VoxelType type = VoxelType::Float32;
    RgbColours colours;
    ~RgbOwner() {
        Registry& r = registry();
        {
            std::lock_guard<std::mutex> lock(r.mutex);
            r.colours.erase(data);
            r.size = r.colours.size();
        }
        std::free(data);
    }
};

RgbColours* find_colours(const Volume& v) {
    Registry& r = registry();
    if (r.size.load(std::memory_order_relaxed) == 0 || !v.data()) return nullptr;
    std::lock_guard<std::mutex> lock(r.mutex);
    const auto it = r.colours.find(v.data());
    if (it == r.colours.end()) return nullptr;
    const RgbOwner& o = *it->second;
    const bool same = o.dims.x == v.dims().x && o.dims.y == v.dims().y && o.dims.z == v.dims().z &&
                      o.type == v.type();
    return same ? &it->second->colours : nullptr;
}

}  // namespace

const RgbColours* rgb_colours(const Volume& v) {
    return find_colours(v);
}

}  // namespace lacuna

namespace lacuna::io {

VoxelType rgb_scalar_type(RgbOpacity o) {
    return o == RgbOpacity::Luminance ? VoxelType::Float32 : VoxelType::UInt8;
}

uint64_t rgb_bytes_per_voxel(RgbOpacity o) {
    return 4 + voxel_size(rgb_scalar_type(o));
}

void check_rgb_opacity(int channels, RgbOpacity o, const std::string& path) {
    if (o == RgbOpacity::A && channels < 4)
        throw Error(path, "rgb opacity",
                    "expected luminance, r, g or b: the file has no alpha channel (RGB24), got a");
}

Volume rgb_volume(Vec3i dims, int channels, RgbOpacity o, const std::string& where) {
    const VoxelType type = rgb_scalar_type(o);
    const size_t count = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
    auto owner = std::make_shared<RgbOwner>();
    // calloc: fresh pages, touched only as data arrives (as Volume's own constructor does).
    owner->data = std::calloc(count, voxel_size(type));
    if (!owner->data)
        throw Error(where, "memory", "out of memory for " + dims_string(dims) + " voxels");
    owner->dims = dims;
    owner->type = type;
    owner->colours.channels = channels;
    owner->colours.opacity = o;
    void* data = owner->data;
    Registry& r = registry();
    {
        std::lock_guard<std::mutex> lock(r.mutex);
        r.colours[data] = owner.get();
        r.size = r.colours.size();
    }
    return Volume(dims, type, std::move(owner), data);
}

void read_rgb_stream(const std::function<size_t(void*, size_t)>& read, Volume& v,
                     const std::string& where, const std::function<void(double)>& progress) {
    RgbColours* colours = find_colours(v);
    if (!colours) throw Error(where, "voxel data", "internal: not a volume of rgb_volume()");
    const size_t count = v.voxel_count();
    const int channels = colours->channels;
    const size_t nc = size_t(channels);
    const RgbOpacity o = colours->opacity;
    // Grown chunk by chunk rather than sized up front: a short compressed stream then fails
    // after touching only the pages its data filled, as the scalar readers do.
    colours->rgba.reserve(count * 4);
    constexpr size_t kStageVoxels = size_t(1) << 20;
    std::vector<uint8_t> stage(std::min(count, kStageVoxels) * nc);
    const int pick = o == RgbOpacity::R ? 0 : o == RgbOpacity::G ? 1 : o == RgbOpacity::B ? 2 : 3;
    size_t first = 0;
    while (first < count) {
        const size_t n = std::min(kStageVoxels, count - first);
        const size_t got = read(stage.data(), n * nc);
        if (got < n * nc)
            throw Error(where, "voxel data",
                        "truncated: expected " + std::to_string(count * nc) + " bytes of " +
                            (channels == 3 ? "RGB24" : "RGBA32") + " voxels, the data ends after " +
                            std::to_string(first * nc + got));
        colours->rgba.resize((first + n) * 4);
        uint8_t* dst = colours->rgba.data() + first * 4;
        for (size_t i = 0; i < n; ++i) {
            const uint8_t* s = &stage[i * nc];
            dst[4 * i + 0] = s[0];
            dst[4 * i + 1] = s[1];
            dst[4 * i + 2] = s[2];
            dst[4 * i + 3] = channels == 4 ? s[3] : 255;
        }
        if (o == RgbOpacity::Luminance) {
            float* out = v.data_as<float>() + first;
            for (size_t i = 0; i < n; ++i)
                out[i] = rgb_luminance(dst[4 * i], dst[4 * i + 1], dst[4 * i + 2]);
        } else {
            uint8_t* out = v.data_as<uint8_t>() + first;
            for (size_t i = 0; i < n; ++i) out[i] = dst[4 * i + pick];
        }
        first += n;
        report(progress, 0.95 * double(first) / double(count));
    }
}

}  // namespace lacuna::io
