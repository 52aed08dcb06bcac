// fuzz_raw: raw names and the CLI's --dims/--type/--range/--max-memory parsing. The input is
// four text lines and the voxels: a file name (kept to [A-Za-z0-9_.x-], at most 80 characters,
// ".raw" appended if missing), then the --dims, --type, --range and --max-memory values (empty
// lines: not given), then the data. It goes through the CLI's own load_volume
// (apps/lacuna/cli_common.cpp), as `lacuna info NAME --dims ... --type ...` would.
#include <string>

#include "../../apps/lacuna/cli_common.h"
#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    std::string lines[5];
    for (auto& line : lines) {
        const auto [l, tail] = split(rest, "\n");
        line.assign(l.substr(0, 200));
        rest = tail;
    }
    std::string name;
    for (char c : lines[0])
        if (name.size() < 80 &&
            (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-'))
            name += c;
    if (name.empty() || name[0] == '.') name = "v" + name;
    if (name.size() < 4 || name.compare(name.size() - 4, 4, ".raw") != 0) name += ".raw";
    const std::string dir = scratch_dir("raw");
    lacuna::cli::VolumeArgs a;
    a.path = put(dir, name, rest);
    a.raw_dims = lines[1];
    a.raw_type = lines[2];
    a.range = lines[3];
    a.max_memory = lines[4].empty() ? std::string("256M") : lines[4];
    try {
        const lacuna::Volume v = lacuna::cli::load_volume(a);
        if (!v.data()) std::abort();
    } catch (const lacuna::Error& e) {
        if (std::string(e.what()).find('\n') != std::string::npos) std::abort();
    }
    return 0;
}
