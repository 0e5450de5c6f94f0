/* scene_builder.h: the scene builder, the interface the scene statements call
 * (core/scene_statements*.c; internal to the parser). The statements read their clauses;
 * the builder holds the structure of the file and fills the scene.
 *
 * What it owns:
 *   - blocks (group, instance, volume) on a stack whose bottom entry is the top level;
 *     each block keeps its own transform (composed in double, affine.h) and its material,
 *     and buffers its direct shapes, which become one contiguous object of the scene when
 *     it closes (so nested blocks cannot interleave their shapes);
 *   - placements: placing an object walks up the stack once: every block's transform
 *     applies in turn, the innermost explicit material and the nearest volume fill in what
 *     is still open, every open named group records the placement relative to its
 *     parent's frame, and the result becomes one scene instance (rounded to float there);
 *   - named groups and their replay: `instance NAME` places what the group recorded again,
 *     through the blocks open at the instance;
 *   - the rules of structure, each with its message: transforms come first in a block,
 *     an instance block holds only transforms, lights stand at the top level, blocks nest
 *     at most 64 deep and close in the file that opens them, names are defined once,
 *     placements are limited (instances of instances multiply);
 *   - where each material, texture and shape was defined, and the last camera statement,
 *     for later messages and for the validation pass (core/scene_validate.c).
 *
 * Return rule: a function that can fail reports one message (scene_report.h) at the
 * position it is given and returns false; running out of memory is RT_ERROR_RUNTIME.
 * The scene is the caller's: the builder adds to it and never frees it (on failure the
 * caller frees it). builder_free frees the builder's own buffers.
 *
 * The struct is defined here so that the parser can hold it; read and change it only
 * through the functions below.
 */
#ifndef RT_SCENE_BUILDER_H
#define RT_SCENE_BUILDER_H

#include <stdbool.h>
#include <stddef.h>

#include "affine.h"
#include "scene.h"
#include "scene_gltf.h"
#include "scene_report.h"

/* Blocks nest at most this deep (the top level does not count). */
#define MAX_BLOCK_DEPTH 64

struct source_file;                  /* scene_lexer.h: a block's file, compared by identity */
struct placement;
struct pending_shape;
struct imported_model;

typedef enum block_kind {
    BLOCK_TOP_LEVEL,
    BLOCK_GROUP,
    BLOCK_INSTANCE,
    BLOCK_VOLUME,
} block_kind;

/* One open block, or the top level (blocks[0]). */
typedef struct scene_block {
    block_kind kind;
    source_position opened;          /* the keyword of its opening line */
    const struct source_file *file;  /* the file that must close it; NULL for the top level */
    affine transform;                /* its own transform statements, composed */
    bool content_seen;               /* anything but a transform or include came */
    int material;                    /* its explicit `material`, or -1 */
    float density, albedo[3];        /* volume */
    int group;                       /* named group: index into builder.groups, else -1 */
    int instance_of;                 /* instance block: the group it places, else -1 */
    int object;                      /* object of its direct shapes, -1 until the first */
    struct pending_shape *shapes;    /* its direct shapes, added to the scene when it closes */
    int shape_count;
    size_t shape_capacity;
} scene_block;

/* A named group: what it placed, relative to its parent's frame, for `instance NAME`. */
typedef struct named_group {
    char name[SCENE_NAME_MAX];
    source_position position;
    bool open;                       /* an instance of an open group would be recursion */
    struct placement *placements;
    int placement_count;
    size_t placement_capacity;
} named_group;

typedef struct scene_builder {
    scene *scene;
    scene_report *report;
    source_position *material_positions;   /* parallel to scene->materials */
    size_t material_position_capacity;
    source_position *texture_positions;    /* parallel to scene->textures */
    size_t texture_position_capacity;
    source_position *shape_positions;      /* parallel to scene->shapes */
    size_t shape_position_capacity;
    int *mesh_objects;                     /* parallel to scene->meshes: each mesh's object */
    size_t mesh_object_capacity;
    named_group *groups;
    int group_count;
    size_t group_capacity;
    int placement_total;                   /* instances and group records, for the limit */
    struct imported_model *imports;        /* glTF models read so far, by path */
    int import_count;
    size_t import_capacity;
    bool camera_seen;
    source_position last_camera;
    /* blocks[0] is the top level; one spare entry above MAX_BLOCK_DEPTH holds the implicit
     * block of an `instance` without braces. */
    scene_block blocks[MAX_BLOCK_DEPTH + 2];
    int block_count;
} scene_builder;

/* ---- the builder itself */

/* Starts building into out (which the caller has set to scene_defaults()); failures go
 * to report. */
void builder_init(scene_builder *builder, scene *out, scene_report *report);

/* Frees the builder's buffers (positions, groups, blocks); never the scene. */
void builder_free(scene_builder *builder);

/* Ends the file: moves the top level's shapes into the scene. */
bool builder_finish(scene_builder *builder);

/* The scene built so far, for lookups (materials by name, the camera's current values). */
const scene *builder_scene(const scene_builder *builder);

/* How many blocks are open (0 at the top level). */
int builder_depth(const scene_builder *builder);

/* ---- settings (the last statement wins) */

/* Sets the camera; where is the statement, for the validation pass's messages. */
void builder_set_camera(scene_builder *builder, const scene_camera *camera, source_position where);

/* Set the render settings, the sky (wholly) and the Whitted ambient term. */
void builder_set_render(scene_builder *builder, const scene_render_settings *render);
void builder_set_sky(scene_builder *builder, const scene_sky *sky);
void builder_set_ambient(scene_builder *builder, const float ambient[3]);

/* The index of the light group called name (scene.h scene_light_group: added when new);
 * -1 when the scene has SCENE_LIGHT_GROUP_MAX already. */
int builder_light_group(scene_builder *builder, const char *name);

/* Fails unless a light may stand here (at the top level); where is its keyword. */
bool builder_check_light_allowed(scene_builder *builder, const source_position *where);

/* Adds a point, spot or sun light (only memory can fail). */
bool builder_add_light(scene_builder *builder, const scene_light *light);

/* ---- materials, textures and images */

/* The kinds of name a scene defines, each once. */
typedef enum name_kind {
    NAME_MATERIAL,
    NAME_TEXTURE,
    NAME_GROUP,
} name_kind;

/* Fails when a material, texture or group (kind) called name is already defined; where
 * is the new name. */
bool builder_check_new_name(scene_builder *builder, name_kind kind, const char *name, const source_position *where);

/* Adds material, defined by the name at where. */
bool builder_add_material(scene_builder *builder, const scene_material *material, source_position where);

/* Adds texture (defined by the statement at where) and sets *index to its index. */
bool builder_add_texture(scene_builder *builder, const scene_texture *texture, source_position where, int *index);

/* Returns the index of the texture called name (length bytes), or -1. The hidden
 * textures that hold a checker's plain colours have an empty name and are never found. */
int builder_find_texture(const scene_builder *builder, const char *name, size_t length);

/* Sets *image to the image of path (resolved), adding it on first use with where as the
 * position the asset loader names: images are shared by path. */
bool builder_add_image(scene_builder *builder, const char *path, source_position where, int *image);

/* Marks image as values, not colours (a normal map): the loader must not sRGB-decode it. */
void builder_mark_image_data(scene_builder *builder, int image);

/* ---- geometry */

/* Starts a statement that adds content to the current block: after it no transform may
 * follow in the block, and an instance block takes nothing but transforms. keyword is
 * the statement's keyword (length bytes, not NUL-terminated; a message quotes it), where
 * its position. */
bool builder_begin_content(scene_builder *builder, const char *keyword, size_t length, const source_position *where);

/* Checks that a transform statement may stand here: inside a block, before its
 * contents; keyword, length and where as for builder_begin_content. */
bool builder_begin_transform(scene_builder *builder, const char *keyword, size_t length,
                             const source_position *where);

/* Makes transform apply after the transforms the current block already has. */
void builder_append_transform(scene_builder *builder, const affine *transform);

/* Adds a sphere: at the top level one of the scene's plain spheres (material >= 0), inside
 * a block a shape of the block's object (material -1: the block's). */
bool builder_add_sphere(scene_builder *builder, const float center[3], float radius, int material,
                        const source_position *where);

/* Adds shape (of the statement at where) to the current block; the block's first shape
 * creates and places its object, whose shapes are filled in when the block closes. */
bool builder_add_shape(scene_builder *builder, const scene_shape *shape, const source_position *where);

/* Places the mesh at path (resolved; one object per path however often it is placed,
 * named at path_where for the asset loader) with material (-1: the block's), for the
 * statement at where. */
bool builder_place_mesh(scene_builder *builder, const char *path, source_position path_where, int material,
                        const source_position *where);

/* ---- imported models (the gltf statement; scene_gltf.h adds their contents) */

/* Returns what the model at path (resolved) placed when a statement imported it before
 * (*count placements; the array stays the builder's), or NULL when none did. */
const scene_gltf_placement *builder_find_import(const scene_builder *builder, const char *path, int *count);

/* Adds the loaded model (from the file at path) to the scene for the statement at where
 * (scene_gltf_add(): its meshes and image bytes move out of model) and records it: the
 * positions of the materials and textures it added, its meshes' objects, and its
 * placements for the next statement naming the same file. */
bool builder_import_model(scene_builder *builder, gltf_model *model, const char *path, source_position where);

/* Places object with transform (in double, relative to the current block's contents) and
 * no material of its own, for the statement at where. */
bool builder_place_object(scene_builder *builder, int object, const affine *transform, const source_position *where);

/* ---- blocks */

/* Opens a group block (its keyword at opened, in file) with material (-1: none); a
 * non-empty name (defined at named) makes it a named group that `instance` can place. */
bool builder_open_group(scene_builder *builder, const char *name, source_position named, int material,
                        source_position opened, const struct source_file *file);

/* Sets *group to the named group called name that an instance at where may place: it
 * must be defined and closed. */
bool builder_find_instanced_group(scene_builder *builder, const char *name, const source_position *where,
                                  int *group);

/* Places group again with material (-1: none) and no transform of its own: an instance
 * statement without braces, at opened. */
bool builder_place_instance(scene_builder *builder, int group, int material, source_position opened);

/* Opens an instance block of group, whose transforms then follow; closing it places the
 * group. */
bool builder_open_instance(scene_builder *builder, int group, int material, source_position opened,
                           const struct source_file *file);

/* Opens a volume block: a constant medium (density, albedo) bounded by its contents. */
bool builder_open_volume(scene_builder *builder, float density, const float albedo[3], source_position opened,
                         const struct source_file *file);

/* Fails unless a '}' at where, in file, may close the current block: one must be open,
 * and file must be the one that opened it. */
bool builder_check_close(scene_builder *builder, const struct source_file *file, const source_position *where);

/* Closes the current block: an instance block places its group; a group or volume moves
 * its shapes into the scene. */
bool builder_close_block(scene_builder *builder);

/* Fails when more blocks are open than depth_before, at the end of the file at path
 * (every file closes the blocks it opens). */
bool builder_check_file_closed(scene_builder *builder, int depth_before, const char *path);

/* ---- for the validation pass */

/* Where the statement of shape index (an index into scene->shapes) stands. */
const source_position *builder_shape_position(const scene_builder *builder, int shape);

/* The last camera statement, or NULL when there was none. */
const source_position *builder_last_camera(const scene_builder *builder);

#endif
