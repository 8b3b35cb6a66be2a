// scenes/shim_util.hpp -- what the scene loaders' C++ shims (gltf_*.cpp, obj_load.cpp) share: the
// path by name for the check that a file a scene names lies inside the scene file's folder (unless
// SFSIM_ALLOW_OUTSIDE_URIS=1), and the numbers and lines of their messages. Internal to the shims.
#ifndef SFSIM_SHIM_UTIL_HPP
#define SFSIM_SHIM_UTIL_HPP

#include <cstdio>
#include <string>
#include <unistd.h>
#include <vector>

namespace scene_shim {

// A number for messages, as printf's %g writes it (1e+30, 0.5, inf).
inline std::string num(double x)
{
    char b[32];
    std::snprintf(b, sizeof b, "%g", x);
    return b;
}

// One line from a library's multi-line error and warning text.
inline std::string one_line(std::string s)
{
    for (char &c : s)
        if (c == '\n' || c == '\r')
            c = ' ';
    while (!s.empty() && s.back() == ' ')
        s.pop_back();
    return s;
}

// path made absolute (from the working directory) with "." and ".." resolved by name alone,
// ending in '/'; "" when the working directory cannot be read.
inline std::string lexical_path(const std::string &path)
{
    std::string full = path;
    if (full.empty() || full[0] != '/') {
        char cwd[4096];
        if (!getcwd(cwd, sizeof cwd))
            return std::string();
        full = std::string(cwd) + "/" + full;
    }
    std::vector<std::string> parts;
    size_t i = 0;
    while (i <= full.size()) {
        size_t j = full.find('/', i);
        if (j == std::string::npos)
            j = full.size();
        std::string part = full.substr(i, j - i);
        if (part == "..") {
            if (!parts.empty())
                parts.pop_back();
        } else if (!part.empty() && part != ".") {
            parts.push_back(part);
        }
        i = j + 1;
    }
    std::string out;
    for (const auto &part : parts)
        out += "/" + part;
    return out + "/";
}

} // namespace scene_shim

#endif
