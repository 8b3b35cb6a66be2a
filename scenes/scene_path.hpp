// scenes/scene_path.hpp -- paths as the scene loaders' shims (gltf_load.cpp, obj_load.cpp) judge
// them, for the check that a file a scene names lies inside the scene file's folder unless the
// user allows otherwise (SFSIM_ALLOW_OUTSIDE_URIS=1). Internal to the C++ shims.
#ifndef SFSIM_SCENE_PATH_HPP
#define SFSIM_SCENE_PATH_HPP

#include <string>
#include <unistd.h>
#include <vector>

// path made absolute (from the working directory) with "." and ".." resolved by name alone,
// ending in '/'; "" when the working directory cannot be read.
inline std::string scene_lexical_path(const std::string &path)
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

#endif
