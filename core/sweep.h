/* sweep.h: sweep tables (render --sweep FILE.tsv|.csv): a header row of scene variable
 * names, then one row per image, each row's values set as `-D NAME=VALUE` would; and the
 * output name of a row. No GL; the render job (render_job.h) renders the rows.
 *
 * Table syntax: fields are separated by tabs (.tsv) or commas (.csv); spaces around a
 * field are dropped; blank lines and lines starting with '#' are skipped. The first
 * other line is the header: variable names (letters, digits and '_', not starting with
 * a digit), each once, at most SWEEP_MAX_COLUMNS. Every following line is a row with
 * exactly one non-empty value per column (a number or an expression, as -D takes). At
 * most SWEEP_MAX_ROWS rows; rows are numbered from 0 in the order written (as a shell
 * loop counts: `light-%02d.png` names the first row's image light-00.png).
 *
 * Output patterns: `{NAME}` is replaced by the row's value of column NAME, then a `%d`
 * conversion (batch.h) by the row number: `light-{light_x}.png`, `row-%03d.exr`.
 *
 * Errors are RT_ERROR_INPUT with the table's path and line: "t.tsv:3: ...".
 */
#ifndef RT_SWEEP_H
#define RT_SWEEP_H

#include <stddef.h>

#include "status.h"

#define SWEEP_MAX_COLUMNS 32
#define SWEEP_MAX_ROWS 100000
#define SWEEP_NAME_MAX 64

typedef struct sweep_table {
    char path[1024];                              /* as loaded, for messages */
    int column_count;
    char names[SWEEP_MAX_COLUMNS][SWEEP_NAME_MAX];
    int header_line;
    int row_count;
    char **values;                                /* row r, column c: values[r * column_count + c] */
    int *lines;                                   /* row r's line in the file */
} sweep_table;

/* Reads the table at path (the separator by its extension: .tsv or .csv) into *out
 * (allocated; free with sweep_table_free()). An unreadable file, another extension, no
 * header, no row, or a malformed line: RT_ERROR_INPUT. */
rt_status sweep_table_load(const char *path, sweep_table *out, rt_error *error);

/* Parses text (the contents of a file called path, for messages) as sweep_table_load(). */
rt_status sweep_table_parse(const char *text, const char *path, char separator, sweep_table *out,
                            rt_error *error);

/* Frees the rows and zeroes *table. */
void sweep_table_free(sweep_table *table);

/* Formats pattern for row (0-based, its number) into name (size bytes): {NAME}
 * by the row's value, then %d by the row number. A {NAME} of no column, an unclosed {,
 * or a bad % conversion: RT_ERROR_INPUT. */
rt_status sweep_output_name(const char *pattern, const sweep_table *table, int row, char *name, size_t size,
                            rt_error *error);

#endif
