// World (patient RAS) options moved into the volume frame (lacuna/orientation.h), where the
// renderers work: every renderer's public entry maps its camera and feature options once, and
// nothing below it knows about orientation. The lattice, the skipping structures and their
// exactness argument live in index space and are untouched by the map.
#pragma once
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"

namespace lacuna {

// Clip planes, the crop box and the light moved by the rigid map `f` (identity: a copy).
// A world crop box on a volume whose axes are not parallel to RAS's (an oblique volume) is no
// longer a box in the volume frame: it becomes six clip planes, appended after the given ones
// (plane 0, the back-TF split, keeps its place), which remove the same samples.
FeatureOptions to_volume_frame(const VolumeFrame& f, const FeatureOptions& world);

// The options with their features moved, or `world` itself when there is nothing to move.
inline const RenderOptions& to_volume_frame(const VolumeFrame& f, const RenderOptions& world,
                                            RenderOptions& storage) {
    if (f.identity || !world.features.any()) return world;
    storage = world;
    storage.features = to_volume_frame(f, world.features);
    return storage;
}

}  // namespace lacuna
