#include "lacuna/camera.h"

#include <cmath>

namespace lacuna {

// World "up" is +z, superior in patient RAS (lacuna/orientation.h), so heads stand upright.
// Azimuth turns about z, elevation lifts toward +z; azimuth 0, elevation 0 is the anterior view
// (the eye on the +y side looking along -y), azimuth 90 the left view (eye on -x). Looking
// straight down or up, "up" on the screen is anterior (+y).
Camera Camera::orbit(const Box3f& bounds, const OrbitParams& p, int width, int height) {
    Camera c;
    c.m_width = width;
    c.m_height = height;
    c.m_projection = p.projection;
    const Vec3f target = p.has_target ? p.target : bounds.center();
    const float radius = 0.5f * length(bounds.extent());
    const float az = p.azimuth_deg * float(M_PI) / 180.f;
    const float el = p.elevation_deg * float(M_PI) / 180.f;
    // Direction from the target to the eye.
    const Vec3f to_eye{-std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
    const float half_fov = 0.5f * p.fov_y_deg * float(M_PI) / 180.f;
    const float aspect = float(width) / float(height);
    const float zoom = p.zoom > 0.f ? p.zoom : 1.f;
    // Fit the bounding sphere into the narrower of the two fields of view.
    const float fit_tan = std::tan(half_fov) * std::min(1.f, aspect);
    float dist = p.distance > 0.f ? p.distance : radius / std::sin(std::atan(fit_tan)) / zoom;
    if (p.projection == Projection::Orthographic) {
        c.m_half_h = radius / std::min(1.f, aspect) / zoom;
        dist = std::max(dist, 2.f * radius + 1.f);  // keep the eye outside the volume
    } else {
        c.m_half_h = std::tan(half_fov);
    }
    c.m_eye = target + to_eye * dist;
    c.m_forward = -to_eye;
    // The image's up: p.up projected onto the view plane (validate() refuses one parallel to
    // the view; the superior default falls back to anterior when the view looks along it).
    Vec3f world_up = p.up;
    if (std::abs(dot(normalize(world_up), c.m_forward)) > 0.999f) world_up = {0, 1, 0};
    c.m_right = normalize(cross(c.m_forward, world_up));
    c.m_up = cross(c.m_right, c.m_forward);
    return c;
}

Camera Camera::from_basis(Vec3f eye, Vec3f forward, Vec3f right, Vec3f up, float half_height,
                          int width, int height, Projection projection) {
    Camera c;
    c.m_eye = eye;
    c.m_forward = forward;
    c.m_right = right;
    c.m_up = up;
    c.m_half_h = half_height;
    c.m_width = width;
    c.m_height = height;
    c.m_projection = projection;
    return c;
}

Ray Camera::generate(float px, float py) const {
    const float aspect = float(m_width) / float(m_height);
    // Pixel centres: ndc in (-1, 1), y up.
    const float sx = (2.f * (px + 0.5f) / float(m_width) - 1.f) * aspect * m_half_h;
    const float sy = (1.f - 2.f * (py + 0.5f) / float(m_height)) * m_half_h;
    if (m_projection == Projection::Orthographic) {
        return {m_eye + m_right * sx + m_up * sy, m_forward};
    }
    return {m_eye, normalize(m_forward + m_right * sx + m_up * sy)};
}

std::string to_string(const Camera& c) {
    return std::string(c.m_projection == Projection::Orthographic ? "ortho" : "persp") + " eye " +
           to_string(c.m_eye) + " forward " + to_string(c.m_forward) + " " +
           std::to_string(c.m_width) + "x" + std::to_string(c.m_height);
}

}  // namespace lacuna
