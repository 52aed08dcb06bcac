// Where a detached header's voxels may come from (.nhdr "data file", .mhd ElementDataFile).
//
// A header is a text file anyone can write, and its data file name is a path: without a rule,
// "data file: /etc/passwd" or "ElementDataFile = /dev/urandom" reads any file or device, and
// `lacuna serve` then ships that file's histogram to a browser. The rule: a data file must be a
// regular file (after following symlinks), in the header's folder or below it (after resolving
// symlinks and ".."), unless ReadOptions::allow_external_data, which lifts only the location
// rule. Both checks run before ITK or our own data reader opens anything.
#pragma once
#include <string>
#include <vector>

namespace lacuna::io {

// Checks one data file named by `header`'s field `field` (a relative name is relative to the
// header's folder). Throws Error(header, field, ...) naming the file and the rule it breaks.
void check_data_file(const std::string& header, const std::string& field, const std::string& name,
                     bool allow_external);

// Parses a NRRD header (.nhdr, or a .nrrd with a "data file" field) up to its blank line and
// applies check_data_file to every data file it names: one name, "LIST" (names on the lines
// after the header) or a "%d" pattern with min, max and step. Returns their paths (empty for
// attached data).
std::vector<std::string> check_nrrd_data_files(const std::string& header, bool allow_external);

}  // namespace lacuna::io
