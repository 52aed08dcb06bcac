#include "lacuna/views.h"

namespace lacuna {

bool named_view(std::string_view name, float& azimuth_deg, float& elevation_deg) {
    struct View {
        std::string_view name;
        float azimuth, elevation;
    };
    // Azimuth about superior (+z) from the anterior view, toward the patient's left; straight
    // down and up are exactly +-90 (Camera::orbit then puts anterior at the top of the screen).
    static constexpr View views[] = {{"anterior", 0.f, 0.f},  {"posterior", 180.f, 0.f},
                                     {"left", 90.f, 0.f},     {"right", 270.f, 0.f},
                                     {"superior", 0.f, 90.f}, {"inferior", 0.f, -90.f}};
    for (const View& v : views)
        if (name == v.name) {
            azimuth_deg = v.azimuth;
            elevation_deg = v.elevation;
            return true;
        }
    return false;
}

}  // namespace lacuna
