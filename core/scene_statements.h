/* scene_statements.h: the scene parser's statements (internal to the parser): one
 * function per statement keyword, and the one table that maps each keyword to its
 * function (core/scene_statements.c).
 *
 * A statement function reads its clauses from its line (the lexer, scene_lexer.h; the
 * values, scene_values.h) and calls the builder (scene_builder.h), which holds the file's
 * structure and fills the scene; it never writes the scene itself. The files:
 *   core/scene_statements.c             the table, lines and files, include, set, camera,
 *                                       render, sky, ambient, and asset paths
 *   core/scene_statements_appearance.c  light, material, texture
 *   core/scene_statements_geometry.c    the shapes, mesh, the transforms and the blocks
 *                                       (group, instance, volume, '}')
 * A new statement is one function here and one entry in the table (docs/scene-format.md
 * documents it, tests/unit/test_scene_parse.c tests it).
 *
 * Return rule: false after one message (the first failure wins; scene_report.h).
 */
#ifndef RT_SCENE_STATEMENTS_H
#define RT_SCENE_STATEMENTS_H

#include <stdbool.h>
#include <stddef.h>

#include "scene_builder.h"
#include "scene_lexer.h"
#include "scene_values.h"

/* Everything one parse holds; core/scene_parse.c makes one per scene_load_* call. */
typedef struct scene_parser {
    scene_report report;
    scene_lexer lexer;
    scene_variables variables;
    scene_builder builder;
} scene_parser;

/* What every statement function is: keyword is the statement's first token, line's
 * cursor stands after it. Statements that add content to a block have had
 * builder_begin_content called by the dispatcher (the table says which). */
typedef bool (*statement_parser)(scene_parser *p, source_line *line, const token *keyword);

/* Reads what follows the clause word names[clause] of a statement into target, the
 * statement's own struct (read_clauses passes it through). */
typedef bool (*clause_reader)(scene_parser *p, source_line *line, int clause, void *target);

/* A statement takes at most this many kinds of clause. */
#define MAX_CLAUSES 16

/* Reads the clauses of a statement to the end of its line, in any order, each at most
 * once: names (count of them) are the clause words, statement names the statement in
 * messages ("camera"), and read_value reads each clause's values into target. */
bool read_clauses(scene_parser *p, source_line *line, const char *statement, const char *const *names, int count,
                  clause_reader read_value, void *target);

/* Parses every line of file in order; the file must close every block it opens. */
bool parse_source(scene_parser *p, const source_file *file);

/* Reads the quoted path of an image for what (e.g. "the sky environment") and sets *image
 * to its index (images are shared by resolved path). */
bool read_image(scene_parser *p, source_line *line, const char *what, int *image);

/* Reads the NAME of a `group NAME` clause of owner ("the point light") and sets *group to
 * its light group's index (scene.h). A name takes letters, digits, '_' and '-' (no '.':
 * it becomes the prefix of EXR channels, NAME.R), at most SCENE_LIGHT_GROUP_NAME_MAX bytes;
 * more than SCENE_LIGHT_GROUP_MAX groups is an error. */
bool read_light_group(scene_parser *p, source_line *line, const char *owner, int *group);

/* Reads a quoted, non-empty path for what (e.g. "the mesh") and resolves it as include
 * paths are: relative to the directory of the file that names it. The caller frees
 * *resolved; *offset gets the string's offset. Whether the file exists is the asset
 * loader's business (it reports the position recorded here). */
bool read_asset_path(source_line *line, const char *what, char **resolved, size_t *offset);

/* The statements (docs/scene-format.md). */
bool statement_include(scene_parser *p, source_line *line, const token *keyword);
bool statement_set(scene_parser *p, source_line *line, const token *keyword);
bool statement_camera(scene_parser *p, source_line *line, const token *keyword);
bool statement_render(scene_parser *p, source_line *line, const token *keyword);
bool statement_sky(scene_parser *p, source_line *line, const token *keyword);
bool statement_ambient(scene_parser *p, source_line *line, const token *keyword);
bool statement_light(scene_parser *p, source_line *line, const token *keyword);
bool statement_texture(scene_parser *p, source_line *line, const token *keyword);
bool statement_material(scene_parser *p, source_line *line, const token *keyword);
bool statement_sphere(scene_parser *p, source_line *line, const token *keyword);
bool statement_moving_sphere(scene_parser *p, source_line *line, const token *keyword);
bool statement_triangle(scene_parser *p, source_line *line, const token *keyword);
bool statement_quad(scene_parser *p, source_line *line, const token *keyword);
bool statement_box(scene_parser *p, source_line *line, const token *keyword);
bool statement_mesh(scene_parser *p, source_line *line, const token *keyword);
bool statement_gltf(scene_parser *p, source_line *line, const token *keyword);
bool statement_group(scene_parser *p, source_line *line, const token *keyword);
bool statement_instance(scene_parser *p, source_line *line, const token *keyword);
bool statement_volume(scene_parser *p, source_line *line, const token *keyword);
bool statement_close(scene_parser *p, source_line *line, const token *keyword);
bool statement_translate(scene_parser *p, source_line *line, const token *keyword);
bool statement_rotate(scene_parser *p, source_line *line, const token *keyword);
bool statement_scale(scene_parser *p, source_line *line, const token *keyword);
bool statement_matrix(scene_parser *p, source_line *line, const token *keyword);

#endif
