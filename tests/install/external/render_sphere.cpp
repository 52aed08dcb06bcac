// Renders a synthetic sphere through the installed library's Session and checks the picture
// has something in it (exit 0), as a user's first program would (docs/library.md).
#include <cstdio>

#include "lacuna/image.h"
#include "lacuna/session.h"
#include "lacuna/synthetic.h"
#include "lacuna/transfer_function.h"

int main(int argc, char** argv) {
    using namespace lacuna;
    SyntheticOptions so;
    so.dims = {32, 32, 32};
    Session session(generate(SyntheticKind::Sphere, so));
    session.set_transfer_function(preset("mr-default"));
    FrameSpec frame;
    frame.width = frame.height = 64;
    frame.features.shading = ShadingModel::Phong;
    const FrameResult r = session.render(frame);
    if (argc > 1) write_png(argv[1], r.image);
    size_t lit = 0;
    for (size_t i = 0; i < r.image.rgba.size(); i += 4) lit += r.image.rgba[i] > 0;
    std::printf("%zu of %d pixels lit, %.1f samples/ray\n", lit, frame.width * frame.height,
                r.stats.samples_per_ray());
    return lit > 0 ? 0 : 1;
}
