/* gltf_internal.h: what the two halves of the glTF shim share (internal to them, C++
 * only): core/gltf_load.cpp reads the file, its accessors, materials and meshes;
 * core/gltf_nodes.cpp walks the node hierarchy of the default scene (transforms,
 * placements, cameras, lights). See gltf_load.h. */
#ifndef RT_GLTF_INTERNAL_H
#define RT_GLTF_INTERNAL_H

#include <tiny_gltf.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "gltf_load.h"

namespace gltf_shim {

/* A reason the file cannot be loaded: thrown inside, turned into an rt_error at the edge. */
struct gltf_failure {
    std::string reason;
};

/* Throws the failure "WHERE: WHAT" (just WHAT when where is empty). */
[[noreturn]] void fail(const std::string &where, const std::string &what);

/* "name[index]", the JSON path of an array element. */
std::string at(const std::string &name, size_t index);

/* A number for a message, with as few digits as show it. */
std::string number(double value);

/* Copies text into a fixed buffer of size bytes, cut to fit. */
void copy_name(char *buffer, size_t size, const std::string &text);

/* Returns value as a float after checking that it lies in [low, high] (fails naming
 * where). */
float checked_factor(double value, double low, double high, const std::string &where);

/* Copies a vector into a malloc'd array (NULL for an empty vector). */
template <typename T> T *to_malloc(const std::vector<T> &values)
{
    if (values.empty())
        return nullptr;
    T *copy = (T *)malloc(values.size() * sizeof(T));
    if (copy == nullptr)
        throw std::bad_alloc();
    memcpy(copy, values.data(), values.size() * sizeof(T));
    return copy;
}


/* What the shim collects besides the model: warnings, each once. */
struct context {
    std::vector<std::string> warnings;
    std::string first_skipped;   /* the first primitive of points or lines, or "" */
    size_t skipped = 0;          /* how many there are */

    void warn(const std::string &warning)
    {
        if (std::find(warnings.begin(), warnings.end(), warning) == warnings.end())
            warnings.push_back(warning);
    }
};

/* What walking the scene's nodes places. */
struct scene_walk {
    std::vector<gltf_placement> placements;
    std::vector<gltf_camera> cameras;
    std::vector<gltf_light> lights;
};

/* Walks the default scene's trees (see gltf_load.h): triangle_counts[i] is mesh i's
 * number of triangles (a mesh without any is not placed). Fails on a bad hierarchy. */
scene_walk walk_nodes(const tinygltf::Model &model, const std::vector<int> &triangle_counts, context *c);

}  // namespace gltf_shim

#endif
