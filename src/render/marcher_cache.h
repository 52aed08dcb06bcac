// The ray marcher's cache of precomputed feature volumes (private to src/render/).
#pragma once
#include <mutex>
#include <string>
#include <vector>

#include "lacuna/renderer.h"

namespace lacuna {

// Precomputed volumes of the feature path, kept between frames (render() is const: a frame may
// fill the cache; frames of one marcher are rendered one at a time, the mutex guards misuse).
struct RayMarcher::Cache {
    std::mutex mutex;
    std::vector<float> grad[3];  // world gradient per voxel (GradientSource::Precomputed)
    std::vector<float> light;    // transmittance toward the light (ShadowOptions::light_volume)
    int light_dims[3] = {0, 0, 0};
    std::string light_key;  // the light, TF and clipping the light volume was made for
};

}  // namespace lacuna
