// Shortest decimal text for TF numbers, used by to_string() and to_json().
//
// to_json() must round-trip exactly (parse(to_json(tf)) == tf) while staying readable ("0.1",
// not "0.10000000149011612"). The JSON reader parses every number as a double and rounds it to
// float, i.e. it rounds twice; the shortest float text nearly always survives that, and
// float_text() falls back to the exact double text of the float when it would not.
#pragma once
#include <charconv>
#include <cstdlib>
#include <string>

namespace lacuna::tf_detail {

inline std::string double_text(double v) {
    char buf[64];
    auto res = std::to_chars(buf, buf + sizeof(buf), v);
    return std::string(buf, res.ptr);
}

inline std::string float_text(float v) {
    char buf[64];
    auto res = std::to_chars(buf, buf + sizeof(buf), v);
    std::string s(buf, res.ptr);
    if (float(std::strtod(s.c_str(), nullptr)) != v) return double_text(double(v));
    return s;
}

}  // namespace lacuna::tf_detail
