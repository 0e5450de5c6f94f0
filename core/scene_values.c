/* scene_values.c: see scene_values.h. */
#include "scene_values.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "array.h"
#include "expression.h"

/* ------------------------------------------------------------------ variables */

void variables_init(scene_variables *variables, scene_report *report)
{
    *variables = (scene_variables){.report = report};
}

void variables_free(scene_variables *variables)
{
    for (int i = 0; i < variables->count; i++)
        free(variables->items[i].name);
    free(variables->items);
    *variables = (scene_variables){.report = variables->report};
}

scene_variable *variables_find(const scene_variables *variables, const char *name, size_t length)
{
    for (int i = 0; i < variables->count; i++) {
        scene_variable *variable = &variables->items[i];
        if (strlen(variable->name) == length && memcmp(variable->name, name, length) == 0)
            return variable;
    }
    return NULL;
}

scene_variable *variables_find_or_add(scene_variables *variables, const char *name, size_t length)
{
    scene_variable *found = variables_find(variables, name, length);
    if (found != NULL)
        return found;
    char *copy = NULL;
    if (!array_reserve((void **)&variables->items, &variables->capacity, (size_t)variables->count + 1,
                       sizeof *variables->items) ||
        (copy = strndup(name, length)) == NULL) {
        fail_out_of_memory(variables->report);
        return NULL;
    }
    scene_variable *added = &variables->items[variables->count++];
    *added = (scene_variable){.name = copy};
    return added;
}

void variables_mention_names_in(scene_variables *variables, const char *text, size_t length)
{
    for (size_t i = 0; i < length; i++) {
        if (text[i] != '$')
            continue;
        size_t name_end = i + 1;
        while (name_end < length && expression_is_variable_name(text + i + 1, name_end - i))
            name_end++;
        scene_variable *used = variables_find(variables, text + i + 1, name_end - i - 1);
        if (used != NULL)
            used->mentioned = true;
    }
}

bool variables_apply_defines(scene_variables *variables, const scene_parse_options *options)
{
    for (int i = 0; i < options->define_count; i++) {
        const scene_define *define = &options->defines[i];
        const char *name = define->name != NULL ? define->name : "";
        if (!expression_is_variable_name(name, strlen(name)))
            return fail_without_position(variables->report, "-D %s=%s: '%s' is not a valid variable name (letters, "
                                         "digits and '_', not starting with a digit)", name,
                                         define->value ? define->value : "", name);
        if (define->value == NULL)
            return fail_without_position(variables->report, "-D %s: missing value (write -D %s=VALUE)", name, name);
        rt_error expression_error;
        int column = 0;
        double value = 0;
        /* Columns count in "NAME=VALUE", the text the user typed after -D. */
        if (expression_evaluate(define->value, strlen(define->value), (int)strlen(name) + 2, NULL, NULL, &value,
                                &column, &expression_error) != RT_OK)
            return fail_without_position(variables->report, "-D %s=%s: column %d: %s", name, define->value, column,
                                         expression_error.message);
        scene_variable *target = variables_find_or_add(variables, name, strlen(name));
        if (target == NULL)
            return false;
        target->value = value;
        target->has_value = true;
        target->from_define = true;
    }
    return true;
}

/* The expression module's view of the variables: only those with a value exist, and
 * every use is remembered for the unused -D check. */
static bool lookup_variable(void *context, const char *name, size_t length, double *value)
{
    scene_variable *found = variables_find(context, name, length);
    if (found == NULL || !found->has_value)
        return false;
    found->mentioned = true;
    *value = found->value;
    return true;
}

bool evaluate_expression(scene_variables *variables, const source_line *line, size_t offset, size_t length,
                         double *value)
{
    rt_error expression_error;
    int column = 0;
    if (expression_evaluate(line->text + offset, length, (int)(offset > INT_MAX - 1 ? INT_MAX - 1 : offset + 1),
                            lookup_variable, variables, value, &column, &expression_error) == RT_OK)
        return true;
    source_position position = {.path = line->file->path, .line = line->number, .column = (size_t)column};
    return fail_at_position(line->file->report, &position, "%s", expression_error.message);
}

/* ------------------------------------------------------------------ numbers */

/* True for [+-] digits [. digits] [e [+-] digits] or [+-] . digits [e ...]: the only
 * bare numbers a statement takes (everything else must be $name or (expression)). */
static bool is_number_literal(const char *text, size_t length)
{
    size_t i = 0, digits = 0;
    if (i < length && (text[i] == '+' || text[i] == '-'))
        i++;
    while (i < length && text[i] >= '0' && text[i] <= '9')
        i++, digits++;
    if (i < length && text[i] == '.') {
        i++;
        while (i < length && text[i] >= '0' && text[i] <= '9')
            i++, digits++;
    }
    if (digits == 0)
        return false;
    if (i < length && (text[i] == 'e' || text[i] == 'E')) {
        i++;
        if (i < length && (text[i] == '+' || text[i] == '-'))
            i++;
        size_t exponent_digits = 0;
        while (i < length && text[i] >= '0' && text[i] <= '9')
            i++, exponent_digits++;
        if (exponent_digits == 0)
            return false;
    }
    return i == length;
}

/* True when text (after an optional sign) spells nan, inf or infinity, in any case. */
static bool spells_non_finite(const char *text, size_t length)
{
    if (length > 0 && (text[0] == '+' || text[0] == '-'))
        text++, length--;
    static const char *const spellings[] = {"nan", "inf", "infinity"};
    for (int i = 0; i < 3; i++)
        if (strlen(spellings[i]) == length && strncasecmp(text, spellings[i], length) == 0)
            return true;
    return false;
}

/* Returns the offset just after the ')' that closes text[0]'s '(', or length + 1 when
 * it never closes. */
static size_t group_end(const char *text, size_t length)
{
    size_t depth = 0;
    for (size_t i = 0; i < length; i++) {
        if (text[i] == '(')
            depth++;
        else if (text[i] == ')' && --depth == 0)
            return i + 1;
    }
    return length + 1;
}

/* Reports why word t (not a literal, $name or expression) is no number for what. */
static bool fail_not_a_number(const source_line *line, const token *t, const char *what)
{
    char found[FOUND_BUFFER];
    const char *text = line->text + t->offset;
    size_t length = t->length;
    if (spells_non_finite(text, length))
        return fail_at(line, t->offset, "expected a number for %s, found %s (NaN and infinity are not allowed)",
                       what, describe_token(line, t, found, sizeof found));
    /* An operator past a leading sign, or a '(' inside, means an unparenthesised expression. */
    bool looks_like_expression = memchr(text, '(', length) != NULL;
    for (size_t i = 1; i < length; i++)
        if (strchr("+-*/^", text[i]) != NULL)
            looks_like_expression = true;
    if (looks_like_expression)
        return fail_at(line, t->offset, "expected a number for %s, found %s (write an expression in "
                       "parentheses, e.g. (2*3))", what, describe_token(line, t, found, sizeof found));
    return fail_at(line, t->offset, "expected a number for %s, found %s", what,
                   describe_token(line, t, found, sizeof found));
}

bool number_from_token(scene_variables *variables, const source_line *line, const token *t, const char *what,
                       double *value)
{
    char found[FOUND_BUFFER];
    if (t->kind != TOKEN_WORD)
        return fail_at(line, t->offset, "expected a number for %s, found %s", what,
                       describe_token(line, t, found, sizeof found));
    const char *text = line->text + t->offset;
    size_t length = t->length;
    if (text[0] == '(') {
        if (!evaluate_expression(variables, line, t->offset, length, value))
            return false;
        if (group_end(text, length) != length)
            return fail_at(line, t->offset, "expected a number for %s, found %s (an expression must be "
                           "entirely inside one pair of parentheses)", what,
                           describe_token(line, t, found, sizeof found));
        return true;
    }
    if (text[0] == '$') {
        if (!expression_is_variable_name(text + 1, length - 1))
            return fail_at(line, t->offset, "expected a number for %s, found %s (a variable is $name; "
                           "write an expression in parentheses, e.g. ($a+1))", what,
                           describe_token(line, t, found, sizeof found));
        return evaluate_expression(variables, line, t->offset, length, value);
    }
    if (!is_number_literal(text, length))
        return fail_not_a_number(line, t, what);
    char *copy = strndup(text, length);
    if (copy == NULL)
        return fail_out_of_memory(line->file->report);
    *value = strtod(copy, NULL);
    free(copy);
    if (!isfinite(*value))
        return fail_at(line, t->offset, "expected a finite number for %s, found %s (out of range)", what,
                       describe_token(line, t, found, sizeof found));
    return true;
}

bool read_number(scene_variables *variables, source_line *line, const char *what, double *value, size_t *offset)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return fail_at(line, t.offset, "expected a number for %s, found end of line", what);
    if (offset != NULL)
        *offset = t.offset;
    return number_from_token(variables, line, &t, what, value);
}

bool to_float(const source_line *line, size_t offset, const char *what, double value, float *out)
{
    if (fabs(value) > FLT_MAX) {
        char number[NUMBER_BUFFER];
        return fail_at(line, offset, "%s is %s, too large for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    }
    *out = (float)value;
    return true;
}

bool read_float(scene_variables *variables, source_line *line, const char *what, float *out, size_t *offset)
{
    double value = 0;
    size_t where = 0;
    if (!read_number(variables, line, what, &value, &where) || !to_float(line, where, what, value, out))
        return false;
    if (offset != NULL)
        *offset = where;
    return true;
}

bool read_positive_float(scene_variables *variables, source_line *line, const char *what, float *out)
{
    double value = 0;
    size_t offset = 0;
    char number[NUMBER_BUFFER];
    if (!read_number(variables, line, what, &value, &offset))
        return false;
    if (!(value > 0))
        return fail_at(line, offset, "%s must be > 0, found %s", what, format_number(number, sizeof number, value));
    if (!to_float(line, offset, what, value, out))
        return false;
    if (*out == 0)
        return fail_at(line, offset, "%s %s is too small for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    return true;
}

bool read_non_negative_float(scene_variables *variables, source_line *line, const char *what, float *out)
{
    double value = 0;
    size_t offset = 0;
    if (!read_number(variables, line, what, &value, &offset))
        return false;
    if (value < 0) {
        char number[NUMBER_BUFFER];
        return fail_at(line, offset, "%s must be >= 0, found %s", what, format_number(number, sizeof number, value));
    }
    return to_float(line, offset, what, value, out);
}

bool read_unit_float(scene_variables *variables, source_line *line, const char *what, float *out)
{
    double value = 0;
    size_t offset = 0;
    if (!read_number(variables, line, what, &value, &offset))
        return false;
    if (!(value >= 0 && value <= 1)) {
        char number[NUMBER_BUFFER];
        return fail_at(line, offset, "%s must be between 0 and 1, found %s", what,
                       format_number(number, sizeof number, value));
    }
    *out = (float)value;
    return true;
}

bool read_integer(scene_variables *variables, source_line *line, const char *what, long long minimum,
                  long long maximum, long long *out)
{
    double value = 0;
    size_t offset = 0;
    if (!read_number(variables, line, what, &value, &offset))
        return false;
    if (value != floor(value) || value < (double)minimum || value > (double)maximum) {
        char number[NUMBER_BUFFER];
        return fail_at(line, offset, "%s must be a whole number from %lld to %lld, found %s", what, minimum, maximum,
                       format_number(number, sizeof number, value));
    }
    *out = (long long)value;
    return true;
}

/* The axes of read_vector and read_point, as the messages name them. */
static const char *const axes[3] = {"x", "y", "z"};

bool read_vector(scene_variables *variables, source_line *line, const char *owner, float out[3], size_t offsets[3])
{
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "%s %s", owner, axes[i]);
        if (!read_float(variables, line, what, &out[i], offsets != NULL ? &offsets[i] : NULL))
            return false;
    }
    return true;
}

bool read_point(scene_variables *variables, source_line *line, const char *owner, double out[3], size_t offsets[3])
{
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "%s %s", owner, axes[i]);
        size_t offset = 0;
        float unused;
        if (!read_number(variables, line, what, &out[i], &offset) || !to_float(line, offset, what, out[i], &unused))
            return false;
        if (offsets != NULL)
            offsets[i] = offset;
    }
    return true;
}

bool read_colour(scene_variables *variables, source_line *line, const char *owner, float out[3])
{
    static const char *const channels[3] = {"red", "green", "blue"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of %s", channels[i], owner);
        if (!read_non_negative_float(variables, line, what, &out[i]))
            return false;
    }
    return true;
}

/* ------------------------------------------------------------------ clause words and names */

bool match_clause(const source_line *line, const token *t, const char *statement, const char *const *names,
                  int count, size_t *first_offsets, int *index)
{
    for (int i = 0; i < count; i++) {
        if (!token_is(line, t, names[i]))
            continue;
        if (first_offsets[i] != SIZE_MAX)
            return fail_at(line, t->offset, "%s clause '%s' given twice in one statement (first at column %zu)",
                           statement, names[i], first_offsets[i] + 1);
        first_offsets[i] = t->offset;
        *index = i;
        return true;
    }
    char expected[DESCRIPTION_BUFFER], found[FOUND_BUFFER];
    return fail_at(line, t->offset, "unknown %s clause %s (expected %s)", statement,
                   describe_token(line, t, found, sizeof found),
                   format_word_list(expected, sizeof expected, names, count));
}

bool is_plain_name(const char *text, size_t length)
{
    for (size_t i = 0; i < length; i++) {
        char c = text[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.'))
            return false;
    }
    return length > 0;
}

bool name_from_token(const source_line *line, const token *t, const char *kind, char name[SCENE_NAME_MAX])
{
    char found[FOUND_BUFFER];
    const char *text = line->text + t->offset;
    if (t->kind != TOKEN_WORD || !is_plain_name(text, t->length))
        return fail_at(line, t->offset, "expected a %s name (letters, digits, '_', '-' and '.'), found %s", kind,
                       describe_token(line, t, found, sizeof found));
    if (t->length > SCENE_NAME_MAX - 1)
        return fail_at(line, t->offset, "%s name %s is %zu bytes long; the limit is %d", kind,
                       describe_token(line, t, found, sizeof found), t->length, SCENE_NAME_MAX - 1);
    memcpy(name, text, t->length);
    name[t->length] = '\0';
    return true;
}

bool read_definition_name(source_line *line, const char *kind, token *t, char name[SCENE_NAME_MAX])
{
    if (!next_token(line, t))
        return false;
    if (t->kind == TOKEN_END)
        return fail_at(line, t->offset, "expected a %s name after %s, found end of line", kind, kind);
    return name_from_token(line, t, kind, name);
}
