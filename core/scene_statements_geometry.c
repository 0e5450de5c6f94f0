/* scene_statements_geometry.c: the statements of what a scene holds and where: the
 * transforms, the shapes, mesh, and the blocks (group, instance, volume, '}'); see
 * scene_statements.h. */
#include "scene_statements.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "affine.h"
#include "gltf_load.h"
#include "scene_gltf.h"

/* ------------------------------------------------------------------ transforms */

/* Checks that the transform statement whose keyword is keyword may stand here. */
static bool begin_transform(scene_parser *p, const source_line *line, const token *keyword)
{
    source_position where = token_position(line, keyword);
    return builder_begin_transform(&p->builder, line->text + keyword->offset, keyword->length, &where);
}

/* translate X Y Z */
bool statement_translate(scene_parser *p, source_line *line, const token *keyword)
{
    double offset[3];
    if (!begin_transform(p, line, keyword) || !read_point(&p->variables, line, "the translation", offset, NULL) ||
        !expect_end_of_line(line, "the translation"))
        return false;
    affine translation = affine_translation(offset);
    builder_append_transform(&p->builder, &translation);
    return true;
}

/* rotate AX AY AZ DEGREES: right-handed, about the axis through the origin. */
bool statement_rotate(scene_parser *p, source_line *line, const token *keyword)
{
    double axis[3], degrees = 0;
    size_t offsets[3];
    if (!begin_transform(p, line, keyword) || !read_point(&p->variables, line, "the rotation axis", axis, offsets) ||
        !read_number(&p->variables, line, "the rotation angle in degrees", &degrees, NULL) ||
        !expect_end_of_line(line, "the rotation"))
        return false;
    double unit[3];
    if (!vector_normalise(axis, unit))
        return fail_at(line, offsets[0], "the rotation axis (0 0 0) has zero length, so it has no direction");
    affine rotation = affine_rotation(unit, degrees);
    builder_append_transform(&p->builder, &rotation);
    return true;
}

/* scale S | scale SX SY SZ: about the origin; negative factors mirror, 0 is an error. */
bool statement_scale(scene_parser *p, source_line *line, const token *keyword)
{
    double factors[3];
    size_t offsets[3];
    token next = {.kind = TOKEN_END};
    if (!begin_transform(p, line, keyword) ||
        !read_number(&p->variables, line, "the scale", &factors[0], &offsets[0]) || !peek_token(line, &next))
        return false;
    if (next.kind == TOKEN_END) {
        factors[1] = factors[2] = factors[0];
        offsets[1] = offsets[2] = offsets[0];
    } else if (!read_number(&p->variables, line, "the scale y", &factors[1], &offsets[1]) ||
               !read_number(&p->variables, line, "the scale z", &factors[2], &offsets[2]) ||
               !expect_end_of_line(line, "the scale")) {
        return false;
    }
    char number[NUMBER_BUFFER];
    for (int i = 0; i < 3; i++) {
        float as_float = 0;
        if (!to_float(line, offsets[i], "the scale", factors[i], &as_float))
            return false;
        if (factors[i] == 0)
            return fail_at(line, offsets[i], "the scale must not be 0 on any axis (it would flatten the contents), "
                           "found 0");
        if (as_float == 0)
            return fail_at(line, offsets[i], "the scale %s is too small for the renderer's 32-bit floats",
                           format_number(number, sizeof number, factors[i]));
    }
    affine scale = affine_scale(factors);
    builder_append_transform(&p->builder, &scale);
    return true;
}

/* matrix M00 M01 M02 M03  M10 .. M13  M20 .. M23: row-major 3x4, world = M p. */
bool statement_matrix(scene_parser *p, source_line *line, const token *keyword)
{
    if (!begin_transform(p, line, keyword))
        return false;
    affine matrix;
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            char what[DESCRIPTION_BUFFER];
            snprintf(what, sizeof what, "the matrix element M%d%d", row, column);
            size_t offset = 0;
            float unused;
            if (!read_number(&p->variables, line, what, &matrix.m[row][column], &offset) ||
                !to_float(line, offset, what, matrix.m[row][column], &unused))
                return false;
        }
    }
    if (!expect_end_of_line(line, "the matrix"))
        return false;
    double determinant = affine_determinant(&matrix);
    if (!(fabs(determinant) >= 1e-12))
        return fail_at(line, keyword->offset, "the matrix is singular (the determinant of its 3x3 part is %g); a "
                       "transform must be invertible", determinant);
    builder_append_transform(&p->builder, &matrix);
    return true;
}

/* ------------------------------------------------------------------ materials of shapes and blocks */

/* Looks up the material named by token t for owner (e.g. "the sphere"); users names the
 * statements that use materials in the hint (e.g. "spheres"). */
static bool material_from_token(scene_parser *p, const source_line *line, const token *t, const char *owner,
                                const char *users, int *material)
{
    char found[FOUND_BUFFER];
    if (t->kind != TOKEN_WORD)
        return fail_at(line, t->offset, "expected a material name for %s, found %s", owner,
                       describe_token(line, t, found, sizeof found));
    *material = -1;
    if (t->length < SCENE_NAME_MAX) {
        char name[SCENE_NAME_MAX];
        memcpy(name, line->text + t->offset, t->length);
        name[t->length] = '\0';
        *material = scene_find_material(builder_scene(&p->builder), name);
    }
    if (*material < 0)
        return fail_at(line, t->offset, "%s's material %s is not defined (a material must be defined before the %s "
                       "that use it)", owner, describe_token(line, t, found, sizeof found), users);
    return true;
}

/* True when token t of line is the name of a material defined so far. */
static bool names_material(scene_parser *p, const source_line *line, const token *t)
{
    char name[SCENE_NAME_MAX];
    if (t->kind != TOKEN_WORD || t->length >= SCENE_NAME_MAX)
        return false;
    memcpy(name, line->text + t->offset, t->length);
    name[t->length] = '\0';
    return scene_find_material(builder_scene(&p->builder), name) >= 0;
}

/* Reads the optional MATERIAL that ends a shape statement for owner ("the sphere"; users
 * is "spheres"), then the end of the line. Inside a block it may be left out (*material
 * -1: the enclosing group's applies); at the top level nothing could supply it. */
static bool read_shape_material(scene_parser *p, source_line *line, const char *owner, const char *users,
                                int *material)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    if (t.kind == TOKEN_END) {
        if (builder_depth(&p->builder) == 0)
            return fail_at(line, t.offset, "expected a material name for %s, found end of line (a shape needs a "
                           "material outside a group)", owner);
        *material = -1;
        return true;
    }
    return material_from_token(p, line, &t, owner, users, material) && expect_end_of_line(line, owner);
}

/* ------------------------------------------------------------------ shapes */

/* Reads the radius of owner ("the sphere"): > 0, and not 0 as a float either. */
static bool read_radius(scene_parser *p, source_line *line, const char *owner, float *radius)
{
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "%s's radius", owner);
    return read_positive_float(&p->variables, line, what, radius);
}

/* sphere X Y Z RADIUS [MATERIAL]: at the top level one of the scene's plain spheres (as in
 * the first version of the format), inside a block a shape of the block's object. */
bool statement_sphere(scene_parser *p, source_line *line, const token *keyword)
{
    float center[3], radius = 0;
    int material = -1;
    if (!read_vector(&p->variables, line, "the sphere's center", center, NULL) ||
        !read_radius(p, line, "the sphere", &radius) ||
        !read_shape_material(p, line, "the sphere", "spheres", &material))
        return false;
    source_position where = token_position(line, keyword);
    return builder_add_sphere(&p->builder, center, radius, material, &where);
}

/* moving_sphere X0 Y0 Z0  X1 Y1 Z1  RADIUS [MATERIAL]: centres at time 0 and time 1. */
bool statement_moving_sphere(scene_parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_MOVING_SPHERE};
    if (!read_vector(&p->variables, line, "the moving sphere's centre at time 0", shape.points[0], NULL) ||
        !read_vector(&p->variables, line, "the moving sphere's centre at time 1", shape.points[1], NULL) ||
        !read_radius(p, line, "the moving sphere", &shape.radius) ||
        !read_shape_material(p, line, "the moving sphere", "moving spheres", &shape.material))
        return false;
    source_position where = token_position(line, keyword);
    return builder_add_shape(&p->builder, &shape, &where);
}

/* The corners of a triangle, as its messages name them. */
static const char *const corners[3] = {"first", "second", "third"};

/* Reads the three corner normals of the triangle's `normals` clause into shape: each three
 * numbers (finite, within the float range), not all zero, stored at unit length. */
static bool read_triangle_normals(scene_parser *p, source_line *line, scene_shape *shape)
{
    for (int k = 0; k < 3; k++) {
        char owner[DESCRIPTION_BUFFER];
        snprintf(owner, sizeof owner, "the triangle's %s normal", corners[k]);
        double normal[3];
        size_t offsets[3];
        if (!read_point(&p->variables, line, owner, normal, offsets))
            return false;
        if (!vector_normalise_to_float(normal, shape->normals[k]))
            return fail_at(line, offsets[0], "%s is zero (0 0 0), so it has no direction (a normal needs a length "
                           "> 0; it is made unit length)", owner);
    }
    shape->has_normals = true;
    return true;
}

/* Reads the three corner texture coordinates of the triangle's `uvs` clause into shape. */
static bool read_triangle_uvs(scene_parser *p, source_line *line, scene_shape *shape)
{
    static const char *const axes[2] = {"u", "v"};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 2; i++) {
            char what[DESCRIPTION_BUFFER];
            snprintf(what, sizeof what, "the triangle's %s uv %s", corners[k], axes[i]);
            if (!read_float(&p->variables, line, what, &shape->uvs[k][i], NULL))
                return false;
        }
    }
    shape->has_uvs = true;
    return true;
}

/* Reads the normals and uvs clauses of a triangle, in either order, each at most once. A
 * clause word that ends the line is the material when a material of that name is
 * defined (so a scene whose material is called `normals` reads as it did). */
static bool read_triangle_clauses(scene_parser *p, source_line *line, scene_shape *shape)
{
    static const char *const clauses[] = {"normals", "uvs"};
    size_t first_offsets[2] = {SIZE_MAX, SIZE_MAX};
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!peek_token(line, &t))
            return false;
        if (!token_is(line, &t, clauses[0]) && !token_is(line, &t, clauses[1]))
            break;
        token word = {.kind = TOKEN_END};
        if (is_last_word(line, &word) && names_material(p, line, &t))
            break;
        int clause = -1;
        if (!next_token(line, &t) || !match_clause(line, &t, "triangle", clauses, 2, first_offsets, &clause))
            return false;
        if (!(clause == 0 ? read_triangle_normals(p, line, shape) : read_triangle_uvs(p, line, shape)))
            return false;
    }
    /* A word that is followed by more and names no material is a misspelt clause. */
    token t = {.kind = TOKEN_END}, word = {.kind = TOKEN_END};
    if (!peek_token(line, &t))
        return false;
    if (t.kind == TOKEN_WORD && !is_last_word(line, &word) && !names_material(p, line, &t)) {
        char found[FOUND_BUFFER];
        return fail_at(line, t.offset, "unknown triangle clause %s (expected normals or uvs, or a material defined "
                       "earlier as the last word)", describe_token(line, &t, found, sizeof found));
    }
    return true;
}

/* triangle X Y Z  X Y Z  X Y Z [normals NX NY NZ  NX NY NZ  NX NY NZ] [uvs U V  U V  U V]
 * [MATERIAL]: counter-clockwise seen from the front. */
bool statement_triangle(scene_parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_TRIANGLE};
    if (!read_vector(&p->variables, line, "the triangle's first corner", shape.points[0], NULL) ||
        !read_vector(&p->variables, line, "the triangle's second corner", shape.points[1], NULL) ||
        !read_vector(&p->variables, line, "the triangle's third corner", shape.points[2], NULL) ||
        !read_triangle_clauses(p, line, &shape) ||
        !read_shape_material(p, line, "the triangle", "triangles", &shape.material))
        return false;
    source_position where = token_position(line, keyword);
    return builder_add_shape(&p->builder, &shape, &where);
}

/* quad QX QY QZ  UX UY UZ  VX VY VZ [MATERIAL]: the parallelogram Q + a u + b v. */
bool statement_quad(scene_parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_QUAD};
    size_t edge_offsets[3];
    if (!read_vector(&p->variables, line, "the quad's corner", shape.points[0], NULL) ||
        !read_vector(&p->variables, line, "the quad's edge u", shape.points[1], edge_offsets) ||
        !read_vector(&p->variables, line, "the quad's edge v", shape.points[2], NULL) ||
        !read_shape_material(p, line, "the quad", "quads", &shape.material))
        return false;
    double u[3], v[3];
    for (int i = 0; i < 3; i++) {
        u[i] = shape.points[1][i];
        v[i] = shape.points[2][i];
    }
    if (vectors_parallel(u, v))
        return fail_at(line, edge_offsets[0], "the quad's edges u (%g %g %g) and v (%g %g %g) are parallel or zero, "
                       "so it has no area", u[0], u[1], u[2], v[0], v[1], v[2]);
    source_position where = token_position(line, keyword);
    return builder_add_shape(&p->builder, &shape, &where);
}

/* box X0 Y0 Z0  X1 Y1 Z1 [MATERIAL]: axis-aligned, from the minimum to the maximum corner;
 * six quads with outward normals (u x v), in the order +X -X +Y -Y +Z -Z. */
bool statement_box(scene_parser *p, source_line *line, const token *keyword)
{
    static const char *const axes[3] = {"x", "y", "z"};
    float low[3], high[3], size[3];
    size_t high_offsets[3];
    int material = -1;
    if (!read_vector(&p->variables, line, "the box's minimum corner", low, NULL) ||
        !read_vector(&p->variables, line, "the box's maximum corner", high, high_offsets) ||
        !read_shape_material(p, line, "the box", "boxes", &material))
        return false;
    for (int i = 0; i < 3; i++) {
        if (!(low[i] < high[i]))
            return fail_at(line, high_offsets[i], "the box's minimum %s (%g) must be less than its maximum %s (%g)",
                           axes[i], low[i], axes[i], high[i]);
        size[i] = high[i] - low[i];
        if (!isfinite(size[i]))
            return fail_at(line, high_offsets[i], "the box's size along %s is too large for the renderer's 32-bit "
                           "floats", axes[i]);
    }
    source_position where = token_position(line, keyword);
    for (int axis = 0; axis < 3; axis++) {
        /* With b, c the next axes in cyclic order, e_b x e_c = e_axis: the + face takes
         * edges (b, c), the - face (c, b). */
        int b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (int side = 0; side < 2; side++) {
            scene_shape quad = {.type = SHAPE_QUAD, .material = material};
            memcpy(quad.points[0], low, sizeof low);
            if (side == 0)
                quad.points[0][axis] = high[axis];
            quad.points[1][side == 0 ? b : c] = size[side == 0 ? b : c];
            quad.points[2][side == 0 ? c : b] = size[side == 0 ? c : b];
            if (!builder_add_shape(&p->builder, &quad, &where))
                return false;
        }
    }
    return true;
}

/* mesh "FILE.obj" | "FILE.ply" [MATERIAL]: one instance of the mesh's object (one per
 * resolved path, however often it is placed); the asset loader reads the file later. */
bool statement_mesh(scene_parser *p, source_line *line, const token *keyword)
{
    char *path = NULL;
    size_t offset = 0;
    int material = -1;
    if (!read_asset_path(line, "the mesh", &path, &offset))
        return false;
    if (scene_gltf_is_model_path(path)) {
        free(path);
        return fail_at(line, offset, "a glTF file is a model, not a mesh: place it with the gltf statement (gltf "
                       "\"FILE\"), which imports its materials and node hierarchy too");
    }
    source_position where = token_position(line, keyword);
    bool placed = read_shape_material(p, line, "the mesh", "meshes", &material) &&
                  builder_place_mesh(&p->builder, path, position_in(line, offset), material, &where);
    free(path);
    return placed;
}

/* Returns the reason of a gltf_load() message "PATH: REASON", or the whole message. */
static const char *gltf_reason(const char *message, const char *path)
{
    size_t length = strlen(path);
    return strncmp(message, path, length) == 0 && strncmp(message + length, ": ", 2) == 0 ? message + length + 2
                                                                                         : message;
}

/* gltf "FILE.gltf" | "FILE.glb": places the model's meshes as its default scene's nodes
 * do, in the current block (its transforms, material and volume apply as to a mesh); the
 * file is read once however often it is placed. Its cameras and lights are not used. */
bool statement_gltf(scene_parser *p, source_line *line, const token *keyword)
{
    char *path = NULL;
    size_t offset = 0;
    if (!read_asset_path(line, "the glTF model", &path, &offset))
        return false;
    source_position where = token_position(line, keyword);
    int count = 0;
    bool ok = expect_end_of_line(line, "the glTF model's path");
    const scene_gltf_placement *placements = ok ? builder_find_import(&p->builder, path, &count) : NULL;
    if (ok && placements == NULL) {
        gltf_model model;
        rt_error inner;
        rt_status status = gltf_load(path, &model, &inner);
        if (status == RT_ERROR_RUNTIME)
            ok = fail_out_of_memory(line->file->report);
        else if (status != RT_OK)
            ok = fail_at(line, offset, "glTF '%s': %s", path, gltf_reason(inner.message, path));
        else
            ok = builder_import_model(&p->builder, &model, path, where);
        gltf_model_free(&model);
        placements = ok ? builder_find_import(&p->builder, path, &count) : NULL;
    }
    for (int i = 0; ok && i < count; i++) {
        affine transform;
        memcpy(transform.m, placements[i].object_to_world, sizeof transform.m);
        ok = builder_place_object(&p->builder, placements[i].object, &transform, &where);
    }
    free(path);
    return ok;
}

/* ------------------------------------------------------------------ blocks */

/* Reads the optional `material MATERIAL` clause of a group or instance line: t holds the
 * token after the name and is advanced past the clause. */
static bool read_block_material(scene_parser *p, source_line *line, token *t, const char *owner, const char *users,
                                int *material)
{
    *material = -1;
    if (!token_is(line, t, "material"))
        return true;
    token name = {.kind = TOKEN_END};
    return lex_token(line, &name, true) && material_from_token(p, line, &name, owner, users, material) &&
           lex_token(line, t, true);
}

/* Checks that t is the '{' that ends the opening line of a block (what: "the group line"). */
static bool expect_open_brace(source_line *line, const token *t, const char *what)
{
    char found[FOUND_BUFFER];
    if (t->kind != TOKEN_OPEN_BRACE)
        return fail_at(line, t->offset, "expected '{' at the end of %s, found %s", what,
                       describe_token(line, t, found, sizeof found));
    return expect_end_of_line(line, "'{' (a block's '{' ends its line)");
}

/* group [NAME] [material MATERIAL] {: opens a block whose contents share its transforms
 * and material; a named group can be placed again with `instance NAME`. */
bool statement_group(scene_parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!lex_token(line, &t, true))
        return false;
    char name[SCENE_NAME_MAX] = "";
    source_position named = {0};
    if (t.kind == TOKEN_WORD && !token_is(line, &t, "material")) {
        named = token_position(line, &t);
        if (!name_from_token(line, &t, "group", name) ||
            !builder_check_new_name(&p->builder, NAME_GROUP, name, &named) || !lex_token(line, &t, true))
            return false;
    }
    int material = -1;
    return read_block_material(p, line, &t, "the group", "groups", &material) &&
           expect_open_brace(line, &t, "the group line") &&
           builder_open_group(&p->builder, name, named, material, token_position(line, keyword), line->file);
}

/* instance NAME [material MATERIAL] [{ transforms }]: places every object the named group
 * placed again, with the block's transforms; MATERIAL fills what has no material yet. */
bool statement_instance(scene_parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return fail_at(line, t.offset, "expected a group name after instance, found end of line");
    char name[SCENE_NAME_MAX];
    int group = -1, material = -1;
    source_position named = token_position(line, &t);
    if (!name_from_token(line, &t, "group", name) ||
        !builder_find_instanced_group(&p->builder, name, &named, &group) || !lex_token(line, &t, true) ||
        !read_block_material(p, line, &t, "the instance", "instances", &material))
        return false;
    source_position opened = token_position(line, keyword);
    if (t.kind == TOKEN_END)
        return builder_place_instance(&p->builder, group, material, opened);
    return expect_open_brace(line, &t, "the instance line (or end of line)") &&
           builder_open_instance(&p->builder, group, material, opened, line->file);
}

/* volume DENSITY R G B {: a constant medium whose boundary is the block's contents. */
bool statement_volume(scene_parser *p, source_line *line, const token *keyword)
{
    static const char *const channels[3] = {"red", "green", "blue"};
    float density = 0, albedo[3];
    if (!read_positive_float(&p->variables, line, "the volume's density", &density))
        return false;
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of the volume's albedo", channels[i]);
        if (!read_unit_float(&p->variables, line, what, &albedo[i]))
            return false;
    }
    token t = {.kind = TOKEN_END};
    return lex_token(line, &t, true) && expect_open_brace(line, &t, "the volume line") &&
           builder_open_volume(&p->builder, density, albedo, token_position(line, keyword), line->file);
}

/* }: closes the current block, which the same file must have opened. An instance block
 * now places its group; a group or volume moves its shapes into the scene. */
bool statement_close(scene_parser *p, source_line *line, const token *keyword)
{
    source_position where = token_position(line, keyword);
    return builder_check_close(&p->builder, line->file, &where) &&
           expect_end_of_line(line, "'}' (a '}' stands alone on its line)") && builder_close_block(&p->builder);
}
