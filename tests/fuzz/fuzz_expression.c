/* fuzz_expression.c: libFuzzer harness for expression_evaluate() (core/expression.c).
 *
 * The input bytes are the expression, passed with their exact length and no terminating
 * NUL (libFuzzer's buffer is exactly sized, so ASan catches any read past the end). The
 * lookup knows a few variables, among them values at the edges of double range, so that
 * overflow checks are reached. Besides crashes and sanitizer reports, the harness aborts
 * when the documented contract breaks: a success gives a finite value; a failure gives a
 * message and a column inside the text (or just past its end).
 *
 * Built by `make fuzz` (see the Makefile); run by tests/fuzz/run.sh. */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "expression.h"

/* The column of the first byte; not 1, so that a column computed from 0 shows up. */
#define BASE_COLUMN 7

/* The variables $x, $y, $zero, $big, $tiny, $neg and $max_double; every other name is
 * undefined. */
static bool lookup_variable(void *context, const char *name, size_t length, double *value)
{
    (void)context;
    static const struct {
        const char *name;
        double value;
    } variables[] = {
        {"x", 1.5}, {"y", -2}, {"zero", 0}, {"big", 1e300}, {"tiny", 1e-300}, {"neg", -1}, {"max_double", 1.7976931348623157e308},
    };
    for (size_t i = 0; i < sizeof variables / sizeof variables[0]; i++)
        if (strlen(variables[i].name) == length && memcmp(variables[i].name, name, length) == 0) {
            *value = variables[i].value;
            return true;
        }
    return false;
}

/* libFuzzer's entry point: evaluates the input once with variables and once without. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    for (int with_variables = 0; with_variables < 2; with_variables++) {
        double value = 0;
        int column = -1;
        rt_error error = {{0}};
        rt_status status = expression_evaluate(text, size, BASE_COLUMN, with_variables ? lookup_variable : NULL,
                                               NULL, &value, &column, &error);
        if (status == RT_OK) {
            if (!isfinite(value))
                abort();
        } else {
            if (status != RT_ERROR_INPUT || error.message[0] == '\0')
                abort();
            if (column < BASE_COLUMN || (size_t)(column - BASE_COLUMN) > size)
                abort();
        }
        /* The same text must be judged the same way without the error outputs. */
        double again = 0;
        if (expression_evaluate(text, size, BASE_COLUMN, with_variables ? lookup_variable : NULL, NULL, &again,
                                NULL, NULL) != status)
            abort();
        if (status == RT_OK && memcmp(&again, &value, sizeof value) != 0)
            abort();
    }
    (void)expression_is_variable_name(text, size);
    return 0;
}
