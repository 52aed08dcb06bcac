// The CLI's edge for FrameSpec (lacuna/frame_spec.h): the library's errors name FrameSpec fields
// ("sampling.step"); the user typed flags ("--step"). One table translates the one to the other,
// so no library error has to know a flag.
#pragma once
#include <string>

#include "lacuna/frame_spec.h"

namespace lacuna::cli {

// The `lacuna render` flag that sets FrameSpec field `field` (the longest listed prefix wins:
// "structure.octree.leaf_cells" -> "--leaf", "structure" -> "--accel").
std::string flag_of_field(const std::string& field);
// A library error's line with the flag the user typed in front, for the errors that name their
// own fields rather than a FrameSpec's ("tf: preset: ..." -> "--tf: tf: preset: ...", the server's
// "serve: host" -> "--host"); other lines unchanged.
std::string with_flag(const std::string& what);
// validate(spec), its FrameError rethrown as lacuna::Error(flag, field, expected).
void validate_flags(const FrameSpec& spec);

}  // namespace lacuna::cli
