// e2e.viewer's helper (tests/e2e/viewer.e2e.mjs): the JPEG `lacuna serve` sends for an image,
// made from a PNG that `lacuna render` wrote. The same encoder (serve/jpeg.h) at the server's
// full-frame quality (ServerOptions::jpeg_quality), so a frame of the viewer and the CLI's image
// of the same settings give the same bytes exactly when the images are the same.
//
// Usage: lacuna_e2e_jpeg IN.png OUT.jpg
#include <cstdio>
#include <exception>
#include <fstream>

#include "lacuna/image.h"
#include "serve/jpeg.h"
#include "serve/server.h"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s IN.png OUT.jpg\n", argv[0]);
        return 2;
    }
    try {
        const std::string jpeg = lacuna::serve::encode_jpeg(
            lacuna::read_png(argv[1]), lacuna::serve::ServerOptions{}.jpeg_quality);
        std::ofstream out(argv[2], std::ios::binary);
        out.write(jpeg.data(), std::streamsize(jpeg.size()));
        if (!out) throw std::runtime_error(std::string("cannot write ") + argv[2]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "lacuna_e2e_jpeg: %s\n", e.what());
        return 1;
    }
    return 0;
}
