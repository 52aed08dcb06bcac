// Named anatomical views (3D Slicer's): the orbit azimuth and elevation (lacuna/camera.h
// OrbitParams) of anterior, posterior, left, right, superior and inferior, in patient RAS (world
// "up" is superior; azimuth 0 is the anterior view, 90 the view from the patient's left). One
// table for `--view` on the command line and the viewer's "camera.view" (docs/cli.md,
// docs/viewer.md), so the two give the same camera.
#pragma once
#include <string_view>

namespace lacuna {

inline constexpr const char* kViewNames = "anterior, posterior, left, right, superior or inferior";

// False (and the angles untouched) for any other name.
bool named_view(std::string_view name, float& azimuth_deg, float& elevation_deg);

}  // namespace lacuna
