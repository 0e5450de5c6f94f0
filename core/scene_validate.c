/* scene_validate.c: see scene_validate.h. */
#include "scene_validate.h"

#include <string.h>

#include "affine.h"

/* A -D that nothing mentions is an error (optional ones, the renderer's own $frame and
 * $time, excepted). */
static bool check_defines_used(const scene_variables *variables, const scene_parse_options *options,
                               scene_report *report)
{
    for (int i = 0; i < options->define_count; i++) {
        const char *name = options->defines[i].name;
        const scene_variable *defined = variables_find(variables, name, strlen(name));
        if (options->defines[i].optional)
            continue;
        if (defined == NULL || !defined->mentioned)
            return fail_without_position(report, "-D %s: the scene never sets or uses $%s", name, name);
    }
    return true;
}

/* The camera's final from, at and up must make a frame. */
static bool check_camera_frame(const scene_builder *builder, scene_report *report)
{
    const source_position *last_camera = builder_last_camera(builder);
    if (last_camera == NULL)
        return true;
    const scene_camera *camera = &builder_scene(builder)->camera;
    double direction[3], up[3];
    for (int i = 0; i < 3; i++) {
        direction[i] = (double)camera->look_at[i] - camera->look_from[i];
        up[i] = camera->up[i];
    }
    if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0)
        return fail_at_position(report, last_camera, "the camera's from and at are the same point (%g %g %g), so it "
                                "has no view direction", camera->look_from[0], camera->look_from[1],
                                camera->look_from[2]);
    if (vectors_parallel(direction, up))
        return fail_at_position(report, last_camera, "the camera's up (%g %g %g) is parallel to its view direction "
                                "(%g %g %g); choose an up that is not", up[0], up[1], up[2], direction[0],
                                direction[1], direction[2]);
    return true;
}

/* Every surface needs a material: a shape without its own takes its instance's, which is
 * -1 when no enclosing group (or instance statement) gave one. A volume's boundary needs
 * none, and a mesh may carry its own (the loader reads usemtl), so only shapes count. */
static bool check_shape_materials(const scene_builder *builder, scene_report *report)
{
    const scene *s = builder_scene(builder);
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if (instance->volume || instance->material >= 0)
            continue;
        const scene_object *object = &s->objects[instance->object];
        for (int k = object->first_shape; k < object->first_shape + object->shape_count; k++)
            if (s->shapes[k].material < 0)
                return fail_at_position(report, builder_shape_position(builder, k), "this shape has no material: "
                                        "give it one, or give a group around it (or the instance that places it) a "
                                        "material");
    }
    return true;
}

/* A volume's boundary must be closed: crossing it is how a ray enters and leaves the
 * medium. Whether a set of surfaces is closed is not cheap to know in general, but the flat
 * shapes (triangles and quads) of one boundary object can only be closed among themselves
 * (a sphere's curved surface never meets a straight edge), and no closed surface is made
 * of fewer than 4 flat faces: so 1 to 3 of them in a volume's object are an open surface
 * for certain (the common mistake: a single quad or triangle). Meshes are checked by the
 * asset loader, which knows their triangles. */
static bool check_volume_boundaries(const scene_builder *builder, scene_report *report)
{
    const scene *s = builder_scene(builder);
    for (int i = 0; i < s->instance_count; i++) {
        if (!s->instances[i].volume)
            continue;
        const scene_object *object = &s->objects[s->instances[i].object];
        int flat = 0, first_flat = -1;
        for (int k = object->first_shape; k < object->first_shape + object->shape_count; k++) {
            if (s->shapes[k].type != SHAPE_TRIANGLE && s->shapes[k].type != SHAPE_QUAD)
                continue;
            if (first_flat < 0)
                first_flat = k;
            flat++;
        }
        if (flat == 0 || flat >= 4)
            continue;
        const char *noun = s->shapes[first_flat].type == SHAPE_QUAD ? "quad" : "triangle";
        const source_position *where = builder_shape_position(builder, first_flat);
        if (flat == 1)
            return fail_at_position(report, where, "this %s is the only flat surface of a volume's boundary, which "
                                    "must be closed: one %s encloses nothing (use a box, a sphere or a closed mesh, "
                                    "or put the %s outside the volume)", noun, noun, noun);
        return fail_at_position(report, where, "this %s is one of only %d flat surfaces (triangles and quads) of a "
                                "volume's boundary, which must be closed: fewer than 4 flat faces enclose nothing "
                                "(use a box, a sphere or a closed mesh)", noun, flat);
    }
    return true;
}

bool validate_scene(const scene_builder *builder, const scene_variables *variables,
                    const scene_parse_options *options, scene_report *report)
{
    return check_defines_used(variables, options, report) && check_camera_frame(builder, report) &&
           check_shape_materials(builder, report) && check_volume_boundaries(builder, report);
}
