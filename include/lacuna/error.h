// lacuna::Error — the one exception type thrown at the library's boundaries (io/, option parsing).
// Its message is a single line: "<where>: <field>: <what was expected, what was found>".
// apps/ catch it, print the line and exit with code 2 (see docs/cli.md).
#pragma once
#include <stdexcept>
#include <string>

namespace lacuna {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
    // where: a file name or option ("ch2.nii.gz", "--tf"); field: the part that is wrong
    // ("dims", "opacity[3].x"); what: what was expected and what was found.
    Error(const std::string& where, const std::string& field, const std::string& what)
        : std::runtime_error(where + ": " + field + ": " + what) {}
};

}  // namespace lacuna
