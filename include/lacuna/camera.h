// Camera: perspective or orthographic, placed by orbit parameters around a target.
// World space is patient RAS in mm (lacuna/orientation.h): +x the patient's right, +y anterior,
// +z superior. The orbit keeps superior up unless OrbitParams::up names another direction.
#pragma once
#include <string>

#include "lacuna/math.h"

namespace lacuna {

enum class Projection { Perspective, Orthographic };

struct Ray {
    Vec3f origin;
    Vec3f dir;  // unit length
};

// Orbit placement around the superior (+z) axis, from the anterior view: azimuth 0, elevation 0
// looks at the face from the front (the eye on +y, looking toward -y), azimuth 90 from the
// patient's left, 180 from behind, 270 from the right; elevation lifts the eye toward superior.
// distance <= 0 means "frame the whole bounds" (the default); zoom > 1 moves closer.
// `up` is the world direction that points up in the image (projected onto the view plane, so it
// need only not be parallel to the view direction): superior by default, which becomes anterior
// when the view looks straight along the superior axis.
struct OrbitParams {
    float azimuth_deg = 30.f;
    float elevation_deg = 20.f;
    float zoom = 1.f;
    float distance = 0.f;
    bool has_target = false;
    Vec3f target{};  // used when has_target; otherwise the centre of the bounds
    Vec3f up{0, 0, 1};
    float fov_y_deg = 30.f;
    Projection projection = Projection::Perspective;
};

class Camera {
  public:
    Camera() = default;
    // A camera that sees all of `bounds` (world box) for the given image size.
    static Camera orbit(const Box3f& bounds, const OrbitParams& p, int width, int height);

    // A camera from its eye and screen basis (right, up: the image's x and y directions; they need
    // not be right-handed with forward, e.g. after a mirroring map into a volume frame).
    static Camera from_basis(Vec3f eye, Vec3f forward, Vec3f right, Vec3f up, float half_height,
                             int width, int height, Projection projection);

    // The ray through the centre of pixel (px, py); py = 0 is the top row.
    Ray generate(float px, float py) const;
    int width() const { return m_width; }
    int height() const { return m_height; }
    Vec3f eye() const { return m_eye; }
    Vec3f forward() const { return m_forward; }
    // The screen basis and half height generate() uses (object-order renderers project with it).
    Vec3f right() const { return m_right; }
    Vec3f up() const { return m_up; }
    float half_height() const { return m_half_h; }
    Projection projection() const { return m_projection; }

  private:
    Vec3f m_eye{}, m_forward{0, 0, -1}, m_right{1, 0, 0}, m_up{0, 1, 0};
    float m_half_h = 1.f;  // tan(fov/2) for perspective; half the view height for orthographic
    int m_width = 1, m_height = 1;
    Projection m_projection = Projection::Perspective;
    friend std::string to_string(const Camera&);
};
std::string to_string(const Camera& c);

}  // namespace lacuna
