/* gltf_nodes.cpp: the glTF shim's node hierarchy (gltf_internal.h): the default scene's
 * trees checked (one parent per node, no cycle), walked depth first with a stack of its
 * own, transforms (matrix or T R S) composed in double, and what the nodes place:
 * meshes, cameras, KHR_lights_punctual lights. See gltf_load.h. */
#include "gltf_internal.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace gltf_shim {
namespace {

/* A 3x4 affine map in double, as gltf_matrix. */
struct affine {
    double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
};

/* Returns a b (b first). */
affine compose(const affine &a, const affine &b)
{
    affine out;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++) {
            double sum = k == 3 ? a.m[r][3] : 0.0;
            for (int j = 0; j < 3; j++)
                sum += a.m[r][j] * b.m[j][k];
            out.m[r][k] = sum;
        }
    return out;
}

/* Checks that a node array property has n values (or none) that are finite. */
void check_numbers(const std::vector<double> &values, size_t n, const std::string &where)
{
    if (!values.empty() && values.size() != n)
        fail(where, "expected " + std::to_string(n) + " numbers, found " + std::to_string(values.size()));
    for (double v : values)
        if (!std::isfinite(v))
            fail(where, "a value is not a finite number");
}

/* The local transform of node index: its matrix (column-major), else T R S. */
affine local_transform(const tinygltf::Node &node, const std::string &where)
{
    check_numbers(node.matrix, 16, where + ".matrix");
    check_numbers(node.translation, 3, where + ".translation");
    check_numbers(node.rotation, 4, where + ".rotation");
    check_numbers(node.scale, 3, where + ".scale");
    affine out;
    if (!node.matrix.empty()) {
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 4; k++)
                out.m[r][k] = node.matrix[(size_t)(k * 4 + r)];
        if (node.matrix[3] != 0 || node.matrix[7] != 0 || node.matrix[11] != 0 || node.matrix[15] != 1)
            fail(where + ".matrix", "the last row must be 0 0 0 1 (a glTF node matrix is affine)");
        return out;
    }
    double q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1}, t[3] = {0, 0, 0};
    for (size_t i = 0; i < node.rotation.size(); i++)
        q[i] = node.rotation[i];
    for (size_t i = 0; i < node.scale.size(); i++)
        s[i] = node.scale[i];
    for (size_t i = 0; i < node.translation.size(); i++)
        t[i] = node.translation[i];
    double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(length > 0) || !std::isfinite(length))
        fail(where + ".rotation", "the quaternion has no length");
    double x = q[0] / length, y = q[1] / length, z = q[2] / length, w = q[3] / length;
    double rotation[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)},
    };
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            out.m[r][k] = rotation[r][k] * s[k];
        out.m[r][3] = t[r];
    }
    return out;
}

/* Copies an affine into a gltf_matrix, checking it fits the renderer's floats. */
void store_matrix(const affine &a, gltf_matrix out, const std::string &where)
{
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++) {
            if (!(std::fabs(a.m[r][k]) <= 3.4028234663852886e38))
                fail(where, "its transform (with its parents') is too large for the renderer's 32-bit floats");
            out[r][k] = a.m[r][k];
        }
}

/* The light index a node's KHR_lights_punctual names, or -1. */
int node_light(const tinygltf::Node &node, size_t light_count, const std::string &where)
{
    auto found = node.extensions.find("KHR_lights_punctual");
    if (found == node.extensions.end() || !found->second.IsObject() || !found->second.Has("light"))
        return -1;
    const tinygltf::Value &value = found->second.Get("light");
    if (!value.IsNumber())
        fail(where + ".extensions.KHR_lights_punctual.light", "expected a light index");
    double index = value.GetNumberAsDouble();
    if (!(index >= 0 && index < (double)light_count) || index != std::floor(index))
        fail(where + ".extensions.KHR_lights_punctual.light", "light " + number(index)
                                                                  + " does not exist (the file has "
                                                                  + std::to_string(light_count) + ")");
    return (int)index;
}

/* Converts KHR_lights_punctual light index, placed by to_world. */
gltf_light convert_light(const tinygltf::Model &model, int index, const affine &to_world, const std::string &node_where)
{
    const tinygltf::Light &light = model.lights[(size_t)index];
    const std::string where = "extensions.KHR_lights_punctual" + at(".lights", (size_t)index);
    gltf_light out;
    memset(&out, 0, sizeof out);
    copy_name(out.name, sizeof out.name, light.name);
    if (light.type == "point")
        out.type = GLTF_LIGHT_POINT;
    else if (light.type == "spot")
        out.type = GLTF_LIGHT_SPOT;
    else if (light.type == "directional")
        out.type = GLTF_LIGHT_DIRECTIONAL;
    else
        fail(where + ".type", "'" + light.type.substr(0, 40) + "' is not point, spot or directional");
    if (!light.color.empty() && light.color.size() != 3)
        fail(where + ".color", "expected 3 numbers, found " + std::to_string(light.color.size()));
    for (int k = 0; k < 3; k++)
        out.color[k] = light.color.empty() ? 1.0f : checked_factor(light.color[(size_t)k], 0, 1, where + ".color");
    out.intensity = checked_factor(light.intensity, 0, 3.4e38, where + ".intensity");
    if (out.type == GLTF_LIGHT_SPOT) {
        out.inner_cone = checked_factor(light.spot.innerConeAngle, 0, M_PI / 2, where + ".spot.innerConeAngle");
        out.outer_cone = checked_factor(light.spot.outerConeAngle, 0, M_PI / 2, where + ".spot.outerConeAngle");
        if (!(out.inner_cone < out.outer_cone) || !(out.outer_cone > 0))
            fail(where + ".spot", "innerConeAngle " + number(out.inner_cone) + " must be less than outerConeAngle "
                                      + number(out.outer_cone));
    }
    store_matrix(to_world, out.light_to_world, node_where);
    return out;
}

/* Converts camera index, placed by to_world. */
gltf_camera convert_camera(const tinygltf::Model &model, int index, const affine &to_world, const std::string &node_where)
{
    const tinygltf::Camera &camera = model.cameras[(size_t)index];
    const std::string where = at("cameras", (size_t)index);
    gltf_camera out;
    memset(&out, 0, sizeof out);
    copy_name(out.name, sizeof out.name, camera.name);
    out.index = index;
    if (camera.type == "orthographic") {
        out.orthographic = true;
    } else if (camera.type == "perspective") {
        double yfov = camera.perspective.yfov;
        if (!(yfov > 0 && yfov < M_PI))
            fail(where + ".perspective.yfov", number(yfov) + " must be between 0 and pi radians (both excluded)");
        double aspect = camera.perspective.aspectRatio;
        if (!(aspect >= 0 && aspect < 1e6))
            fail(where + ".perspective.aspectRatio", number(aspect) + " must be a positive number");
        out.yfov = yfov;
        out.aspect_ratio = aspect;
    } else {
        fail(where + ".type", "'" + camera.type.substr(0, 40) + "' is not perspective or orthographic");
    }
    store_matrix(to_world, out.camera_to_world, node_where);
    return out;
}

/* The root nodes of the default scene; checks them. */
std::vector<int> scene_roots(const tinygltf::Model &model, const std::vector<int> &parent)
{
    std::vector<int> roots;
    if (model.scenes.empty()) {
        if (model.defaultScene >= 0)
            fail("scene", "scene " + std::to_string(model.defaultScene) + " does not exist (the file has none)");
        for (size_t n = 0; n < model.nodes.size(); n++)
            if (parent[n] < 0)
                roots.push_back((int)n);
        return roots;
    }
    int chosen = model.defaultScene >= 0 ? model.defaultScene : 0;
    if ((size_t)chosen >= model.scenes.size())
        fail("scene", "scene " + std::to_string(chosen) + " does not exist (the file has "
                          + std::to_string(model.scenes.size()) + ")");
    const std::string where = at("scenes", (size_t)chosen) + ".nodes";
    std::vector<bool> listed(model.nodes.size(), false);
    for (int n : model.scenes[(size_t)chosen].nodes) {
        if (n < 0 || (size_t)n >= model.nodes.size())
            fail(where, "node " + std::to_string(n) + " does not exist (the file has " + std::to_string(model.nodes.size())
                            + ")");
        if (parent[(size_t)n] >= 0)
            fail(where, "node " + std::to_string(n) + " is a child of nodes[" + std::to_string(parent[(size_t)n])
                            + "], not a root");
        if (listed[(size_t)n])
            fail(where, "node " + std::to_string(n) + " is listed twice");
        listed[(size_t)n] = true;
        roots.push_back(n);
    }
    return roots;
}

/* Walks the default scene's trees depth first (with a stack of its own: a chain of nodes
 * as deep as the file is long must not exhaust the C stack), composing transforms. */
}  // namespace

scene_walk walk_nodes(const tinygltf::Model &model, const std::vector<int> &triangle_counts, context *c)
{
    const size_t count = model.nodes.size();
    std::vector<int> parent(count, -1);
    for (size_t n = 0; n < count; n++) {
        const std::string where = at("nodes", n) + ".children";
        for (int child : model.nodes[n].children) {
            if (child < 0 || (size_t)child >= count)
                fail(where, "node " + std::to_string(child) + " does not exist (the file has " + std::to_string(count)
                                + ")");
            if ((size_t)child == n)
                fail(where, "the node is its own child (the node hierarchy has a cycle)");
            if (parent[(size_t)child] >= 0)
                fail(where, "node " + std::to_string(child) + " is already a child of nodes["
                                + std::to_string(parent[(size_t)child]) + "] (a node has at most one parent)");
            parent[(size_t)child] = (int)n;
        }
    }
    /* A cycle of nodes that are each other's parents has no root, so no walk from the
     * scene would meet it: follow every node's parents up instead, each node once. */
    std::vector<size_t> seen_by(count, SIZE_MAX);
    for (size_t n = 0; n < count; n++) {
        size_t up = n;
        while (seen_by[up] == SIZE_MAX) {
            seen_by[up] = n;
            if (parent[up] < 0)
                break;
            size_t child = up;
            up = (size_t)parent[up];
            if (seen_by[up] == n)
                fail(at("nodes", up) + ".children", "node " + std::to_string(child) + " is an ancestor of "
                                                        + at("nodes", up) + " (the node hierarchy has a cycle)");
        }
    }
    std::vector<int> roots = scene_roots(model, parent);
    scene_walk walk;
    /* state: 0 unvisited, 1 on the current path, 2 done. */
    std::vector<char> state(count, 0);
    struct frame {
        int node;
        affine to_world;
        size_t next_child;
    };
    std::vector<frame> stack;
    for (int root : roots) {
        stack.push_back({root, local_transform(model.nodes[(size_t)root], at("nodes", (size_t)root)), 0});
        state[(size_t)root] = 1;
        while (!stack.empty()) {
            frame &top = stack.back();
            const tinygltf::Node &node = model.nodes[(size_t)top.node];
            const std::string where = at("nodes", (size_t)top.node);
            if (top.next_child == 0) {
                /* First visit: what the node places. */
                if (node.mesh >= 0 || node.mesh < -1) {
                    if ((size_t)node.mesh >= triangle_counts.size())
                        fail(where + ".mesh", "mesh " + std::to_string(node.mesh) + " does not exist (the file has "
                                                  + std::to_string(triangle_counts.size()) + ")");
                    if (node.skin >= 0)
                        c->warn(where + ": skinning is ignored (the mesh is placed in its bind pose)");
                    if (triangle_counts[(size_t)node.mesh] > 0) {
                        gltf_placement placement;
                        memset(&placement, 0, sizeof placement);
                        placement.mesh = node.mesh;
                        copy_name(placement.node_name, sizeof placement.node_name, node.name);
                        store_matrix(top.to_world, placement.object_to_world, where);
                        walk.placements.push_back(placement);
                    }
                }
                if (node.camera >= 0 || node.camera < -1) {
                    if ((size_t)node.camera >= model.cameras.size())
                        fail(where + ".camera", "camera " + std::to_string(node.camera) + " does not exist (the file has "
                                                    + std::to_string(model.cameras.size()) + ")");
                    walk.cameras.push_back(convert_camera(model, node.camera, top.to_world, where));
                    copy_name(walk.cameras.back().node_name, sizeof walk.cameras.back().node_name, node.name);
                }
                int light = node_light(node, model.lights.size(), where);
                if (light >= 0)
                    walk.lights.push_back(convert_light(model, light, top.to_world, where));
            }
            if (top.next_child == node.children.size()) {
                state[(size_t)top.node] = 2;
                stack.pop_back();
                continue;
            }
            int child = node.children[top.next_child++];
            if (state[(size_t)child] == 1)
                fail(where + ".children", "node " + std::to_string(child) + " is an ancestor of " + where
                                              + " (the node hierarchy has a cycle)");
            affine child_world = compose(top.to_world, local_transform(model.nodes[(size_t)child], at("nodes", (size_t)child)));
            state[(size_t)child] = 1;
            stack.push_back({child, child_world, 0});
        }
    }
    return walk;
}

}  // namespace gltf_shim
