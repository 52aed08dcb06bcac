// The viewer's page, embedded at build time by web/embed.cmake (web/*.html, *.js, *.css).
// The HTTP server answers GET requests only from this table: a request's path is a key, never a
// file name, so nothing the browser sends can open a file.
#pragma once
#include <string_view>
#include <vector>

namespace lacuna::serve {

struct Asset {
    std::string_view path;          // "/index.html"
    std::string_view content_type;  // "text/html; charset=utf-8"
    std::string_view body;
};

const std::vector<Asset>& assets();

}  // namespace lacuna::serve
