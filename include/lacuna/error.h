// lacuna::Error — the one exception type thrown at the library's boundaries (io/, option parsing).
// Its message is a single line: "<where>: <field>: <what was expected, what was found>".
// apps/ catch it, print the line and exit with code 2 (see docs/cli.md).
#pragma once
#include <stdexcept>
#include <string>
#include <utility>

namespace lacuna {

class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
    // where: a file name or option ("ch2.nii.gz", "--tf"); field: the part that is wrong
    // ("dims", "opacity[3].x"); what: what was expected and what was found.
    Error(const std::string& where, const std::string& field, const std::string& what)
        : std::runtime_error(where + ": " + field + ": " + what) {}
};

// An option of a frame out of range or not taken: `field` is the FrameSpec field at fault
// ("sampling.step", "features.phong", "structure.bits"; lacuna/frame_spec.h), `expected` what was
// expected and what was found; what() is "frame: <field>: <expected>". The library's renderers,
// structures and validate() throw it; a front end translates the field into its own vocabulary
// (the CLI into its flags, apps/lacuna/frame_flags.cpp; Python into its keywords).
class FrameError : public Error {
  public:
    FrameError(std::string field, std::string expected)
        : Error("frame", field, expected),
          m_field(std::move(field)),
          m_expected(std::move(expected)) {}
    const std::string& field() const { return m_field; }
    const std::string& expected() const { return m_expected; }

  private:
    std::string m_field, m_expected;
};

}  // namespace lacuna
