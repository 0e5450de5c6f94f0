/* scene_values.h: the values of a statement's clauses, read from its line (internal to
 * the parser, core/scene_*.c): numbers, whole numbers, vectors, colours, names and the
 * clause words themselves; and the variables ($NAME) numbers may use.
 *
 * Numbers: a bare literal ([+-] digits [. digits] [e [+-] digits]), a $variable or an
 * expression in one pair of parentheses (core/expression.h evaluates it, in double);
 * nothing else, so that `2*3` or `nan` get a message that says what to write. Every
 * number read is finite; a reader that stores a float also checks that the value fits a
 * float (the renderer's), and the range readers check their range, in the order: the
 * number, its range, its float.
 *
 * Variables: `set NAME EXPRESSION` and -D NAME=VALUE define them; a -D define is
 * evaluated before the file is read and wins over the file's `set`. Each variable
 * remembers whether the scene set or used it, for the check that every -D is used
 * (core/scene_validate.c).
 *
 * Return rule: a reader returns false after reporting one message at the offending token
 * (through the line's report, scene_lexer.h); `what` and `owner` name the value in that
 * message ("the sphere's radius", "material 'red'"). The variables own their names
 * (variables_free frees them).
 */
#ifndef RT_SCENE_VALUES_H
#define RT_SCENE_VALUES_H

#include <stdbool.h>
#include <stddef.h>

#include "scene.h"
#include "scene_lexer.h"
#include "scene_parse.h"

typedef struct scene_variable {
    char *name;                      /* without '$'; owned */
    double value;
    bool has_value;
    bool from_define;                /* a -D define: the file's `set` of it is skipped */
    bool mentioned;                  /* set or used by the scene, for the unused -D check */
} scene_variable;

typedef struct scene_variables {
    scene_report *report;
    scene_variable *items;
    int count;
    size_t capacity;
} scene_variables;

/* ---- variables */

/* Starts an empty set of variables that reports to report. */
void variables_init(scene_variables *variables, scene_report *report);

/* Frees the variables and their names. */
void variables_free(scene_variables *variables);

/* Returns the variable called name (length bytes), or NULL. Linear: scenes have few. */
scene_variable *variables_find(const scene_variables *variables, const char *name, size_t length);

/* Returns the variable called name, adding an unset one if there is none; NULL when
 * memory runs out (reported). */
scene_variable *variables_find_or_add(scene_variables *variables, const char *name, size_t length);

/* Marks every $name in the text (length bytes) as used: an expression that a -D skips
 * still uses the variables it names, so that `-D a=1 -D b=2` with `set a $b` does not
 * call -D b unused. */
void variables_mention_names_in(scene_variables *variables, const char *text, size_t length);

/* Evaluates the -D defines of options (before the file is read, so that they exist from
 * line 1). Reports a bad name, a missing value or an expression error, without position. */
bool variables_apply_defines(scene_variables *variables, const scene_parse_options *options);

/* Evaluates length bytes of line at offset as an expression into *value; on failure
 * reports the evaluator's message at its column. */
bool evaluate_expression(scene_variables *variables, const source_line *line, size_t offset, size_t length,
                         double *value);

/* ---- numbers */

/* Evaluates token t as a number for what: a literal, a $variable or a parenthesised
 * expression. */
bool number_from_token(scene_variables *variables, const source_line *line, const token *t, const char *what,
                       double *value);

/* Reads the next token as a number for what; *offset (when not NULL) gets the token's
 * offset for later range errors. */
bool read_number(scene_variables *variables, source_line *line, const char *what, double *value, size_t *offset);

/* Stores value as a float in *out, failing at offset when it is too large for one: the
 * renderer works in 32-bit floats, and a value that is finite in double may not be. */
bool to_float(const source_line *line, size_t offset, const char *what, double value, float *out);

/* Reads a number that must fit a float; *offset as read_number. */
bool read_float(scene_variables *variables, source_line *line, const char *what, float *out, size_t *offset);

/* Reads a number > 0 that fits a float and is not 0 as a float either (a radius, a
 * scale, a density, an index of refraction, a phong exponent). */
bool read_positive_float(scene_variables *variables, source_line *line, const char *what, float *out);

/* Reads a number >= 0 that fits a float (a colour component, an intensity). */
bool read_non_negative_float(scene_variables *variables, source_line *line, const char *what, float *out);

/* Reads a number from 0 to 1 (a specular or albedo component). */
bool read_unit_float(scene_variables *variables, source_line *line, const char *what, float *out);

/* Reads a whole number in [minimum, maximum]. */
bool read_integer(scene_variables *variables, source_line *line, const char *what, long long minimum,
                  long long maximum, long long *out);

/* Reads three numbers x y z for owner ("the camera's from" -> "the camera's from x");
 * offsets (when not NULL) get each token's offset. */
bool read_vector(scene_variables *variables, source_line *line, const char *owner, float out[3], size_t offsets[3]);

/* The same in double, for transforms and directions (affine.h says why double); each
 * value must still fit a float, as everything the renderer gets does. */
bool read_point(scene_variables *variables, source_line *line, const char *owner, double out[3], size_t offsets[3]);

/* Reads three colour components R G B for owner ("the red component of OWNER"), each >= 0. */
bool read_colour(scene_variables *variables, source_line *line, const char *owner, float out[3]);

/* ---- clause words and names */

/* Matches t against the clause names of a statement and sets *index. A clause seen twice
 * in one statement is an error (the second probably meant another clause): first_offsets
 * (count entries, SIZE_MAX before the first) remember where each came. An unknown word
 * is reported with the list of the clauses. */
bool match_clause(const source_line *line, const token *t, const char *statement, const char *const *names,
                  int count, size_t *first_offsets, int *index);

/* True for a name of a material, texture or group: letters, digits, '_', '-' and '.',
 * at least one, so that a name is never mistaken for a number, a $variable, an
 * expression or a @texture reference. */
bool is_plain_name(const char *text, size_t length);

/* Checks that token t is a valid name for kind ("material", "texture", "group") being
 * defined and copies it into name. */
bool name_from_token(const source_line *line, const token *t, const char *kind, char name[SCENE_NAME_MAX]);

/* Reads the name after `material NAME` or `texture NAME` (*t gets its token). */
bool read_definition_name(source_line *line, const char *kind, token *t, char name[SCENE_NAME_MAX]);

#endif
