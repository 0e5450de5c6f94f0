/* scene_builder.c: see scene_builder.h (blocks, placements, group replay, the rules of
 * structure). */
#include "scene_builder.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"

/* Instances plus the placements named groups remember, together: flattening instances of
 * instances multiplies, and a short hostile file must not exhaust memory. */
#define MAX_PLACEMENTS (1 << 22)

/* One placement of an object, relative to some frame, with what is still open: material
 * -1 is filled by an enclosing material, volume false by an enclosing volume. */
typedef struct placement {
    int object;
    affine transform;
    int material;
    bool volume;
    float density;
    float volume_albedo[3];
} placement;

/* A model imported by a gltf statement: what it placed, for the next statement naming it. */
typedef struct imported_model {
    char path[1024];
    scene_gltf_placement *placements;
    int count;
} imported_model;

/* A shape of a block, kept until the block closes so that its object's shapes are
 * contiguous in the scene even when nested blocks add theirs in between. */
typedef struct pending_shape {
    scene_shape shape;
    source_position position;        /* of its statement */
} pending_shape;

/* ------------------------------------------------------------------ the builder itself */

/* Returns an open block of kind with nothing in it yet. */
static scene_block empty_block(block_kind kind)
{
    return (scene_block){
        .kind = kind, .transform = affine_identity(), .material = -1, .group = -1, .instance_of = -1, .object = -1,
    };
}

void builder_init(scene_builder *builder, scene *out, scene_report *report)
{
    *builder = (scene_builder){.scene = out, .report = report};
    builder->blocks[0] = empty_block(BLOCK_TOP_LEVEL);
    builder->block_count = 1;
}

void builder_free(scene_builder *builder)
{
    free(builder->material_positions);
    free(builder->texture_positions);
    free(builder->shape_positions);
    free(builder->mesh_objects);
    for (int i = 0; i < builder->group_count; i++)
        free(builder->groups[i].placements);
    free(builder->groups);
    for (int i = 0; i < builder->import_count; i++)
        free(builder->imports[i].placements);
    free(builder->imports);
    for (int i = 0; i < builder->block_count; i++)
        free(builder->blocks[i].shapes);
    builder->block_count = 0;
}

const scene *builder_scene(const scene_builder *builder)
{
    return builder->scene;
}

int builder_light_group(scene_builder *builder, const char *name)
{
    return scene_light_group(builder->scene, name);
}

int builder_depth(const scene_builder *builder)
{
    return builder->block_count - 1;
}

/* The block whose contents the current statement adds to (the top level when none is open). */
static scene_block *current_block(scene_builder *builder)
{
    return &builder->blocks[builder->block_count - 1];
}

/* Names a kind of block in messages. */
static const char *block_noun(block_kind kind)
{
    switch (kind) {
    case BLOCK_GROUP:
        return "group";
    case BLOCK_INSTANCE:
        return "instance block";
    case BLOCK_VOLUME:
        return "volume";
    default:
        return "top level";
    }
}

/* Stores position at index of a parallel position array (index is at most one past the
 * last element stored). */
static bool remember_position(scene_builder *builder, source_position **positions, size_t *capacity, int index,
                              source_position position)
{
    if (!array_reserve((void **)positions, capacity, (size_t)index + 1, sizeof **positions))
        return fail_out_of_memory(builder->report);
    (*positions)[index] = position;
    return true;
}

/* ------------------------------------------------------------------ settings */

void builder_set_camera(scene_builder *builder, const scene_camera *camera, source_position where)
{
    builder->scene->camera = *camera;
    builder->camera_seen = true;
    builder->last_camera = where;
}

void builder_set_render(scene_builder *builder, const scene_render_settings *render)
{
    builder->scene->render = *render;
}

void builder_set_sky(scene_builder *builder, const scene_sky *sky)
{
    builder->scene->sky = *sky;
}

void builder_set_ambient(scene_builder *builder, const float ambient[3])
{
    memcpy(builder->scene->ambient, ambient, sizeof builder->scene->ambient);
}

bool builder_check_light_allowed(scene_builder *builder, const source_position *where)
{
    if (builder->block_count == 1)
        return true;
    const scene_block *b = current_block(builder);
    return fail_at_position(builder->report, where, "lights go at the top level of a scene, not inside a group (this "
                            "light is inside the %s opened at %s:%d:%zu)", block_noun(b->kind), b->opened.path,
                            b->opened.line, b->opened.column);
}

bool builder_add_light(scene_builder *builder, const scene_light *light)
{
    return scene_add_light(builder->scene, light) >= 0 || fail_out_of_memory(builder->report);
}

/* ------------------------------------------------------------------ names */

/* Returns the index of the named group called name, or -1. */
static int find_group(const scene_builder *builder, const char *name)
{
    for (int i = 0; i < builder->group_count; i++)
        if (strcmp(builder->groups[i].name, name) == 0)
            return i;
    return -1;
}

bool builder_check_new_name(scene_builder *builder, name_kind kind, const char *name, const source_position *where)
{
    static const char *const nouns[] = {"material", "texture", "group"};
    const source_position *first = NULL;
    int existing = -1;
    if (kind == NAME_MATERIAL && (existing = scene_find_material(builder->scene, name)) >= 0)
        first = &builder->material_positions[existing];
    else if (kind == NAME_TEXTURE && (existing = builder_find_texture(builder, name, strlen(name))) >= 0)
        first = &builder->texture_positions[existing];
    else if (kind == NAME_GROUP && (existing = find_group(builder, name)) >= 0)
        first = &builder->groups[existing].position;
    if (first == NULL)
        return true;
    return fail_at_position(builder->report, where, "%s '%s' is already defined at %s:%d:%zu", nouns[kind], name,
                            first->path, first->line, first->column);
}

/* ------------------------------------------------------------------ materials, textures and images */

bool builder_add_material(scene_builder *builder, const scene_material *material, source_position where)
{
    int index = scene_add_material(builder->scene, material);
    if (index < 0)
        return fail_out_of_memory(builder->report);
    return remember_position(builder, &builder->material_positions, &builder->material_position_capacity, index,
                             where);
}

int builder_find_texture(const scene_builder *builder, const char *name, size_t length)
{
    const scene *s = builder->scene;
    for (int i = 0; i < s->texture_count; i++)
        if (strlen(s->textures[i].name) == length && length > 0 && memcmp(s->textures[i].name, name, length) == 0)
            return i;
    return -1;
}

bool builder_add_texture(scene_builder *builder, const scene_texture *texture, source_position where, int *index)
{
    *index = scene_add_texture(builder->scene, texture);
    if (*index < 0)
        return fail_out_of_memory(builder->report);
    return remember_position(builder, &builder->texture_positions, &builder->texture_position_capacity, *index,
                             where);
}

bool builder_add_image(scene_builder *builder, const char *path, source_position where, int *image)
{
    scene *s = builder->scene;
    for (int i = 0; i < s->image_count; i++) {
        /* An image of a glTF model (its bytes in the scene) only has a name, not a file. */
        if (s->images[i].encoded == NULL && strcmp(s->images[i].path, path) == 0) {
            *image = i;
            return true;
        }
    }
    scene_image added;
    memset(&added, 0, sizeof added);
    memcpy(added.path, path, strlen(path) + 1);
    format_position(added.position, sizeof added.position, &where);
    *image = scene_add_image(s, &added);
    return *image >= 0 || fail_out_of_memory(builder->report);
}

void builder_mark_image_data(scene_builder *builder, int image)
{
    builder->scene->images[image].data = true;
}

/* ------------------------------------------------------------------ placements */

/* Counts one more instance or group record against MAX_PLACEMENTS; where is the statement
 * that causes it. */
static bool count_placement(scene_builder *builder, const source_position *where)
{
    if (builder->placement_total >= MAX_PLACEMENTS)
        return fail_at_position(builder->report, where, "the scene places too many objects: more than %d instances "
                                "and group placements together (instances of groups of instances multiply)",
                                MAX_PLACEMENTS);
    builder->placement_total++;
    return true;
}

/* Places local (relative to the current block's contents) through every open block, as
 * scene_builder.h describes, and adds the resulting scene instance. */
static bool place_object(scene_builder *builder, const placement *local, const source_position *where)
{
    placement placed = *local;
    for (int k = builder->block_count - 1; k >= 1; k--) {
        const scene_block *b = &builder->blocks[k];
        placed.transform = affine_compose(&b->transform, &placed.transform);
        if (placed.material < 0)
            placed.material = b->material;
        if (!placed.volume && b->kind == BLOCK_VOLUME) {
            placed.volume = true;
            placed.density = b->density;
            memcpy(placed.volume_albedo, b->albedo, sizeof placed.volume_albedo);
        }
        if (b->group < 0)
            continue;
        named_group *group = &builder->groups[b->group];
        if (!count_placement(builder, where))
            return false;
        if (!array_reserve((void **)&group->placements, &group->placement_capacity,
                           (size_t)group->placement_count + 1, sizeof *group->placements))
            return fail_out_of_memory(builder->report);
        group->placements[group->placement_count++] = placed;
    }
    scene_instance instance = {
        .object = placed.object, .material = placed.material, .volume = placed.volume,
        .density = placed.density,
    };
    memcpy(instance.volume_albedo, placed.volume_albedo, sizeof instance.volume_albedo);
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            double value = placed.transform.m[row][column];
            if (!(fabs(value) <= FLT_MAX))
                return fail_at_position(builder->report, where, "the transforms around this statement place it at "
                                        "a scale or distance too large for the renderer's 32-bit floats (%g)", value);
            instance.object_to_world[row][column] = (float)value;
        }
    }
    if (!count_placement(builder, where))
        return false;
    return scene_add_instance(builder->scene, &instance) >= 0 || fail_out_of_memory(builder->report);
}

/* Places every placement group made again, through the current blocks (whose top is the
 * instance block with the instance's own transform and material). */
static bool place_group(scene_builder *builder, int group, const source_position *where)
{
    for (int i = 0; i < builder->groups[group].placement_count; i++) {
        /* A copy: placing records into the enclosing groups, never into this closed one,
         * but the copy keeps that reasoning out of the way. */
        placement recorded = builder->groups[group].placements[i];
        if (!place_object(builder, &recorded, where))
            return false;
    }
    return true;
}

/* Moves a block's buffered shapes into the scene, contiguous, as its object's shapes. */
static bool flush_block_shapes(scene_builder *builder, scene_block *b)
{
    if (b->object < 0)
        return true;
    scene *s = builder->scene;
    s->objects[b->object].first_shape = s->shape_count;
    for (int i = 0; i < b->shape_count; i++) {
        int index = scene_add_shape(s, &b->shapes[i].shape);
        if (index < 0)
            return fail_out_of_memory(builder->report);
        if (!remember_position(builder, &builder->shape_positions, &builder->shape_position_capacity, index,
                               b->shapes[i].position))
            return false;
    }
    s->objects[b->object].shape_count = b->shape_count;
    return true;
}

bool builder_finish(scene_builder *builder)
{
    return flush_block_shapes(builder, &builder->blocks[0]);
}

/* ------------------------------------------------------------------ geometry */

bool builder_begin_content(scene_builder *builder, const char *keyword, size_t length, const source_position *where)
{
    scene_block *b = current_block(builder);
    char word[QUOTE_BUFFER];
    if (b->kind == BLOCK_INSTANCE)
        return fail_at_position(builder->report, where, "only transforms (translate, rotate, scale, matrix) may "
                                "appear inside an instance block, found %s",
                                quote_text(word, sizeof word, keyword, length));
    b->content_seen = true;
    return true;
}

bool builder_begin_transform(scene_builder *builder, const char *keyword, size_t length,
                             const source_position *where)
{
    char word[QUOTE_BUFFER];
    if (builder->block_count == 1)
        return fail_at_position(builder->report, where, "%s outside a block: a transform applies to the contents of "
                                "a group, instance or volume", quote_text(word, sizeof word, keyword, length));
    const scene_block *b = current_block(builder);
    if (b->content_seen)
        return fail_at_position(builder->report, where, "%s after the %s's contents: transforms come first in a "
                                "group (before its shapes, meshes, groups, instances and volumes)",
                                quote_text(word, sizeof word, keyword, length), block_noun(b->kind));
    return true;
}

void builder_append_transform(scene_builder *builder, const affine *transform)
{
    scene_block *b = current_block(builder);
    b->transform = affine_compose(transform, &b->transform);
}

bool builder_add_shape(scene_builder *builder, const scene_shape *shape, const source_position *where)
{
    scene_block *b = current_block(builder);
    if (b->object < 0) {
        scene_object object = {.first_shape = 0, .shape_count = 0, .mesh = -1};
        b->object = scene_add_object(builder->scene, &object);
        if (b->object < 0)
            return fail_out_of_memory(builder->report);
        placement local = {.object = b->object, .transform = affine_identity(), .material = -1};
        if (!place_object(builder, &local, where))
            return false;
    }
    if (!array_reserve((void **)&b->shapes, &b->shape_capacity, (size_t)b->shape_count + 1, sizeof *b->shapes))
        return fail_out_of_memory(builder->report);
    b->shapes[b->shape_count++] = (pending_shape){.shape = *shape, .position = *where};
    return true;
}

bool builder_add_sphere(scene_builder *builder, const float center[3], float radius, int material,
                        const source_position *where)
{
    if (builder->block_count == 1) {
        scene_sphere sphere = {.center = {center[0], center[1], center[2]}, .radius = radius, .material = material};
        return scene_add_sphere(builder->scene, &sphere) >= 0 || fail_out_of_memory(builder->report);
    }
    scene_shape shape = {.type = SHAPE_SPHERE, .material = material, .radius = radius};
    memcpy(shape.points[0], center, sizeof shape.points[0]);
    return builder_add_shape(builder, &shape, where);
}

/* Returns the object of the mesh at path in *object, adding the mesh (named at
 * path_where) and its object on first use. */
static bool find_or_add_mesh_object(scene_builder *builder, const char *path, source_position path_where, int *object)
{
    scene *s = builder->scene;
    int mesh = 0;
    while (mesh < s->mesh_count && strcmp(s->meshes[mesh].path, path) != 0)
        mesh++;
    if (mesh == s->mesh_count) {
        scene_mesh added;
        memset(&added, 0, sizeof added);
        memcpy(added.path, path, strlen(path) + 1);
        format_position(added.position, sizeof added.position, &path_where);
        added.default_material = -1;
        scene_object object_of_mesh = {.first_shape = 0, .shape_count = 0, .mesh = mesh};
        if (scene_add_mesh(s, &added) < 0)
            return fail_out_of_memory(builder->report);
        int object_index = scene_add_object(s, &object_of_mesh);
        if (object_index < 0 || !array_reserve((void **)&builder->mesh_objects, &builder->mesh_object_capacity,
                                               (size_t)mesh + 1, sizeof *builder->mesh_objects))
            return fail_out_of_memory(builder->report);
        builder->mesh_objects[mesh] = object_index;
    }
    *object = builder->mesh_objects[mesh];
    return true;
}

bool builder_place_mesh(scene_builder *builder, const char *path, source_position path_where, int material,
                        const source_position *where)
{
    int object = -1;
    if (!find_or_add_mesh_object(builder, path, path_where, &object))
        return false;
    placement local = {.object = object, .transform = affine_identity(), .material = material};
    return place_object(builder, &local, where);
}

/* ------------------------------------------------------------------ imported models */

const scene_gltf_placement *builder_find_import(const scene_builder *builder, const char *path, int *count)
{
    for (int i = 0; i < builder->import_count; i++) {
        if (strcmp(builder->imports[i].path, path) == 0) {
            *count = builder->imports[i].count;
            return builder->imports[i].placements;
        }
    }
    *count = 0;
    return NULL;
}

/* Records what scene_gltf_add() added for the statement at where (builder_import_model). */
static bool record_import(scene_builder *builder, const char *path, const scene_gltf_contents *contents,
                          source_position where)
{
    scene *s = builder->scene;
    for (int i = contents->first_material; i < s->material_count; i++)
        if (!remember_position(builder, &builder->material_positions, &builder->material_position_capacity, i, where))
            return false;
    for (int i = contents->first_texture; i < s->texture_count; i++)
        if (!remember_position(builder, &builder->texture_positions, &builder->texture_position_capacity, i, where))
            return false;
    /* An imported mesh's object, as find_or_add_mesh_object keeps them (its path names no
     * file, but a mesh statement could still spell it). */
    if (s->mesh_count > contents->first_mesh &&
        !array_reserve((void **)&builder->mesh_objects, &builder->mesh_object_capacity, (size_t)s->mesh_count,
                       sizeof *builder->mesh_objects))
        return fail_out_of_memory(builder->report);
    for (int o = 0; o < s->object_count; o++)
        if (s->objects[o].mesh >= contents->first_mesh)
            builder->mesh_objects[s->objects[o].mesh] = o;
    if (!array_reserve((void **)&builder->imports, &builder->import_capacity, (size_t)builder->import_count + 1,
                       sizeof *builder->imports))
        return fail_out_of_memory(builder->report);
    imported_model *model = &builder->imports[builder->import_count];
    memset(model, 0, sizeof *model);
    snprintf(model->path, sizeof model->path, "%s", path);
    size_t n = contents->placement_count > 0 ? (size_t)contents->placement_count : 1;
    model->placements = malloc(n * sizeof *model->placements);
    if (model->placements == NULL)
        return fail_out_of_memory(builder->report);
    if (contents->placement_count > 0)
        memcpy(model->placements, contents->placements, (size_t)contents->placement_count * sizeof *model->placements);
    model->count = contents->placement_count;
    builder->import_count++;
    return true;
}

bool builder_import_model(scene_builder *builder, gltf_model *model, const char *path, source_position where)
{
    char position[256];
    format_position(position, sizeof position, &where);
    scene_gltf_contents contents;
    rt_error ignored;
    /* scene_gltf_add fails only when memory runs out. */
    if (scene_gltf_add(builder->scene, model, path, position, &contents, &ignored) != RT_OK)
        return fail_out_of_memory(builder->report);
    bool recorded = record_import(builder, path, &contents, where);
    scene_gltf_contents_free(&contents);
    return recorded;
}

bool builder_place_object(scene_builder *builder, int object, const affine *transform, const source_position *where)
{
    placement local = {.object = object, .transform = *transform, .material = -1};
    return place_object(builder, &local, where);
}

/* ------------------------------------------------------------------ blocks */

/* Opens a block of kind whose keyword is at opened, in file; an implicit block (the
 * instance statement without braces) is not counted against MAX_BLOCK_DEPTH. Returns the
 * block, or NULL when it would nest too deeply (reported). */
static scene_block *open_block(scene_builder *builder, block_kind kind, source_position opened,
                               const struct source_file *file, bool implicit)
{
    if (!implicit && builder->block_count - 1 >= MAX_BLOCK_DEPTH) {
        fail_at_position(builder->report, &opened, "blocks nested too deeply: this %s would be level %d, the limit "
                         "is %d", block_noun(kind), builder->block_count, MAX_BLOCK_DEPTH);
        return NULL;
    }
    scene_block *b = &builder->blocks[builder->block_count++];
    *b = empty_block(kind);
    b->opened = opened;
    b->file = file;
    return b;
}

/* Closes the current block (its contents already handled) and frees its buffers. */
static void pop_block(scene_builder *builder)
{
    free(current_block(builder)->shapes);
    builder->block_count--;
}

bool builder_open_group(scene_builder *builder, const char *name, source_position named, int material,
                        source_position opened, const struct source_file *file)
{
    scene_block *b = open_block(builder, BLOCK_GROUP, opened, file, false);
    if (b == NULL)
        return false;
    b->material = material;
    if (name[0] == '\0')
        return true;
    if (!array_reserve((void **)&builder->groups, &builder->group_capacity, (size_t)builder->group_count + 1,
                       sizeof *builder->groups))
        return fail_out_of_memory(builder->report);
    named_group *group = &builder->groups[builder->group_count];
    *group = (named_group){.position = named, .open = true};
    memcpy(group->name, name, sizeof group->name);
    b->group = builder->group_count++;
    return true;
}

bool builder_find_instanced_group(scene_builder *builder, const char *name, const source_position *where,
                                  int *group)
{
    *group = find_group(builder, name);
    if (*group < 0)
        return fail_at_position(builder->report, where, "unknown group '%s' (a group must be defined with group %s "
                                "{ ... } before it is instanced)", name, name);
    if (builder->groups[*group].open)
        return fail_at_position(builder->report, where, "group '%s' is still open: a group cannot contain an "
                                "instance of itself", name);
    return true;
}

bool builder_place_instance(scene_builder *builder, int group, int material, source_position opened)
{
    /* An implicit instance block with no transform, closed at once. */
    scene_block *b = open_block(builder, BLOCK_INSTANCE, opened, NULL, true);
    b->material = material;
    bool placed = place_group(builder, group, &b->opened);
    pop_block(builder);
    return placed;
}

bool builder_open_instance(scene_builder *builder, int group, int material, source_position opened,
                           const struct source_file *file)
{
    scene_block *b = open_block(builder, BLOCK_INSTANCE, opened, file, false);
    if (b == NULL)
        return false;
    b->material = material;
    b->instance_of = group;
    return true;
}

bool builder_open_volume(scene_builder *builder, float density, const float albedo[3], source_position opened,
                         const struct source_file *file)
{
    scene_block *b = open_block(builder, BLOCK_VOLUME, opened, file, false);
    if (b == NULL)
        return false;
    b->density = density;
    memcpy(b->albedo, albedo, sizeof b->albedo);
    return true;
}

bool builder_check_close(scene_builder *builder, const struct source_file *file, const source_position *where)
{
    if (builder->block_count == 1)
        return fail_at_position(builder->report, where, "unexpected '}' (no block is open)");
    const scene_block *b = current_block(builder);
    if (b->file != file)
        return fail_at_position(builder->report, where, "unexpected '}': this file opened no block (the open %s was "
                                "opened at %s:%d:%zu; a block must be closed in the file that opens it)",
                                block_noun(b->kind), b->opened.path, b->opened.line, b->opened.column);
    return true;
}

bool builder_close_block(scene_builder *builder)
{
    scene_block *b = current_block(builder);
    if (b->kind == BLOCK_INSTANCE) {
        if (!place_group(builder, b->instance_of, &b->opened))
            return false;
    } else {
        if (!flush_block_shapes(builder, b))
            return false;
        if (b->group >= 0)
            builder->groups[b->group].open = false;
    }
    pop_block(builder);
    return true;
}

bool builder_check_file_closed(scene_builder *builder, int depth_before, const char *path)
{
    if (builder_depth(builder) == depth_before)
        return true;
    const scene_block *unclosed = current_block(builder);
    return fail_at_position(builder->report, &unclosed->opened, "this %s is never closed (expected a '}' on a line "
                            "of its own before the end of %s)", block_noun(unclosed->kind), path);
}

/* ------------------------------------------------------------------ for the validation pass */

const source_position *builder_shape_position(const scene_builder *builder, int shape)
{
    return &builder->shape_positions[shape];
}

const source_position *builder_last_camera(const scene_builder *builder)
{
    return builder->camera_seen ? &builder->last_camera : NULL;
}
