// JPEG encoding of rendered frames (libjpeg-turbo), for the viewer's WebSocket.
#pragma once
#include <string>

#include "lacuna/image.h"

namespace lacuna::serve {

// Encodes the RGB of an RGBA image (alpha dropped) at `quality` (1..100, baseline, 4:2:0).
// Throws lacuna::Error on an empty image or an encoder failure.
std::string encode_jpeg(const Image& img, int quality = 85);

}  // namespace lacuna::serve
