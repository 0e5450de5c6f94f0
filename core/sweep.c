/* sweep.c: see sweep.h. */
#include "sweep.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "batch.h"
#include "paths.h"

void sweep_table_free(sweep_table *table)
{
    for (int i = 0; table->values != NULL && i < table->row_count * table->column_count; i++)
        free(table->values[i]);
    free(table->values);
    free(table->lines);
    memset(table, 0, sizeof *table);
}

/* Splits line (length bytes, no newline) at separator into at most max fields, each
 * trimmed of spaces, copied into fields[i] (allocated; the caller frees them). Returns
 * how many fields the line has (it may be more than max: the rest are not copied), or -1
 * when memory runs out. */
static int split_fields(const char *line, size_t length, char separator, char **fields, int max)
{
    int count = 0;
    size_t start = 0;
    for (;;) {
        size_t end = start;
        while (end < length && line[end] != separator)
            end++;
        size_t first = start, last = end;
        while (first < last && isspace((unsigned char)line[first]))
            first++;
        while (last > first && isspace((unsigned char)line[last - 1]))
            last--;
        if (count < max) {
            fields[count] = malloc(last - first + 1);
            if (fields[count] == NULL)
                return -1;
            memcpy(fields[count], line + first, last - first);
            fields[count][last - first] = '\0';
        }
        count++;
        if (end >= length)
            return count;
        start = end + 1;
    }
}

/* True for a variable name: letters, digits and '_', not starting with a digit. */
static bool is_variable_name(const char *text)
{
    if (text[0] == '\0' || isdigit((unsigned char)text[0]))
        return false;
    for (const char *c = text; *c != '\0'; c++)
        if (!isalnum((unsigned char)*c) && *c != '_')
            return false;
    return true;
}

/* Reads the header's fields into table; false with *error set when one is not a name or
 * comes twice. */
static bool read_header(sweep_table *table, char **fields, int count, int line, rt_error *error)
{
    if (count > SWEEP_MAX_COLUMNS) {
        rt_error_set(error, RT_ERROR_INPUT, "%s:%d: %d columns; a sweep table has at most %d", table->path, line,
                     count, SWEEP_MAX_COLUMNS);
        return false;
    }
    for (int c = 0; c < count; c++) {
        if (!is_variable_name(fields[c]) || strlen(fields[c]) >= SWEEP_NAME_MAX) {
            rt_error_set(error, RT_ERROR_INPUT,
                         "%s:%d: column %d's name '%s' is not a scene variable name (letters, digits and '_')",
                         table->path, line, c + 1, fields[c]);
            return false;
        }
        for (int k = 0; k < c; k++)
            if (strcmp(fields[k], fields[c]) == 0) {
                rt_error_set(error, RT_ERROR_INPUT, "%s:%d: column '%s' is named twice", table->path, line,
                             fields[c]);
                return false;
            }
        snprintf(table->names[c], SWEEP_NAME_MAX, "%s", fields[c]);
    }
    table->column_count = count;
    table->header_line = line;
    return true;
}

/* Appends a row of table->column_count fields (taken over: the table frees them); false
 * with *error set when a value is missing or memory runs out. */
static bool add_row(sweep_table *table, char **fields, int count, int line, size_t *capacity, size_t *line_capacity,
                    rt_error *error)
{
    if (count != table->column_count) {
        rt_error_set(error, RT_ERROR_INPUT, "%s:%d: %d value%s, but the header (line %d) names %d column%s",
                     table->path, line, count, count == 1 ? "" : "s", table->header_line, table->column_count,
                     table->column_count == 1 ? "" : "s");
        return false;
    }
    for (int c = 0; c < count; c++)
        if (fields[c][0] == '\0') {
            rt_error_set(error, RT_ERROR_INPUT, "%s:%d: no value for column '%s'", table->path, line,
                         table->names[c]);
            return false;
        }
    if (table->row_count == SWEEP_MAX_ROWS) {
        rt_error_set(error, RT_ERROR_INPUT, "%s:%d: more than %d rows", table->path, line, SWEEP_MAX_ROWS);
        return false;
    }
    size_t cells = (size_t)(table->row_count + 1) * table->column_count;
    if (!array_reserve((void **)&table->values, capacity, cells, sizeof *table->values) ||
        !array_reserve((void **)&table->lines, line_capacity, (size_t)table->row_count + 1, sizeof *table->lines)) {
        rt_error_set(error, RT_ERROR_RUNTIME, "out of memory reading %s", table->path);
        return false;
    }
    memcpy(table->values + (size_t)table->row_count * table->column_count, fields, count * sizeof *fields);
    table->lines[table->row_count++] = line;
    return true;
}

rt_status sweep_table_parse(const char *text, const char *path, char separator, sweep_table *out,
                            rt_error *error)
{
    memset(out, 0, sizeof *out);
    snprintf(out->path, sizeof out->path, "%s", path);
    size_t capacity = 0, line_capacity = 0;
    int line = 0;
    bool header = false;
    const char *start = text;
    while (*start != '\0') {
        const char *end = strchr(start, '\n');
        size_t length = end != NULL ? (size_t)(end - start) : strlen(start);
        line++;
        const char *next = end != NULL ? end + 1 : start + length;
        if (length > 0 && start[length - 1] == '\r')
            length--;
        size_t first = 0;
        while (first < length && isspace((unsigned char)start[first]))
            first++;
        if (first == length || start[first] == '#') {
            start = next;
            continue;
        }
        char *fields[SWEEP_MAX_COLUMNS + 1] = {0};
        int count = split_fields(start, length, separator, fields, SWEEP_MAX_COLUMNS + 1);
        int kept = count < SWEEP_MAX_COLUMNS + 1 ? count : SWEEP_MAX_COLUMNS + 1;
        bool ok = count >= 0;
        rt_status failure = count >= 0 ? RT_ERROR_INPUT : RT_ERROR_RUNTIME;
        if (!ok)
            rt_error_set(error, RT_ERROR_RUNTIME, "out of memory reading %s", path);
        else if (!header)
            ok = header = read_header(out, fields, count, line, error);
        else if ((ok = add_row(out, fields, count, line, &capacity, &line_capacity, error)))
            kept = 0;   /* the table owns them now */
        for (int i = 0; i < kept; i++)
            free(fields[i]);
        if (!ok) {
            sweep_table_free(out);
            return failure;
        }
        start = next;
    }
    if (!header || out->row_count == 0) {
        rt_status status = rt_error_set(error, RT_ERROR_INPUT, "%s: %s", path,
                                        !header ? "no header row of variable names" : "a header but no row");
        sweep_table_free(out);
        return status;
    }
    return RT_OK;
}

rt_status sweep_table_load(const char *path, sweep_table *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    const char *extension = path_extension(path);
    char separator = strcmp(extension, ".tsv") == 0 ? '\t' : strcmp(extension, ".csv") == 0 ? ',' : '\0';
    if (separator == '\0')
        return rt_error_set(error, RT_ERROR_INPUT, "%s: a sweep table is a .tsv (tabs) or .csv (commas) file", path);
    FILE *file = fopen(path, "rb");
    if (file == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "%s: cannot read the sweep table", path);
    char *text = NULL;
    size_t size = 0, capacity = 0;
    for (;;) {
        if (!array_reserve((void **)&text, &capacity, size + 4097, 1)) {
            fclose(file);
            free(text);
            return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory reading %s", path);
        }
        size_t got = fread(text + size, 1, 4096, file);
        size += got;
        if (got < 4096)
            break;
    }
    fclose(file);
    text[size] = '\0';
    if (strlen(text) != size) {
        free(text);
        return rt_error_set(error, RT_ERROR_INPUT, "%s: the sweep table holds a NUL byte", path);
    }
    rt_status status = sweep_table_parse(text, path, separator, out, error);
    free(text);
    return status;
}

rt_status sweep_output_name(const char *pattern, const sweep_table *table, int row, char *name, size_t size,
                            rt_error *error)
{
    char expanded[4096];
    size_t used = 0;
    for (const char *c = pattern; *c != '\0'; c++) {
        const char *insert = c;
        size_t length = 1;
        if (*c == '{') {
            const char *close = strchr(c, '}');
            if (close == NULL)
                return rt_error_set(error, RT_ERROR_INPUT, "the output pattern '%s' has a '{' without its '}'",
                                    pattern);
            int column = 0;
            while (column < table->column_count && (strlen(table->names[column]) != (size_t)(close - c - 1) ||
                                                    strncmp(table->names[column], c + 1, (size_t)(close - c - 1)) != 0))
                column++;
            if (column == table->column_count)
                return rt_error_set(error, RT_ERROR_INPUT, "the output pattern's {%.*s} is no column of %s",
                                    (int)(close - c - 1), c + 1, table->path);
            /* The value is text of the name, never a conversion: its '%' are doubled. */
            for (const char *v = table->values[(size_t)row * table->column_count + column]; *v != '\0'; v++) {
                if (used + 2 >= sizeof expanded)
                    return rt_error_set(error, RT_ERROR_INPUT, "the output name of row %d is too long", row);
                if (*v == '%')
                    expanded[used++] = '%';
                expanded[used++] = *v;
            }
            c = close;
            continue;
        }
        if (used + length >= sizeof expanded)
            return rt_error_set(error, RT_ERROR_INPUT, "the output name of row %d is too long", row);
        memcpy(expanded + used, insert, length);
        used += length;
    }
    expanded[used] = '\0';
    return output_pattern_format(expanded, row, name, size, error);
}
