/* expression.h: evaluates the arithmetic expressions of the scene format, in double.
 *
 * Used by the scene parser (core/scene_values.c, core/scene_statements.c) for numbers
 * written as `( ... )`, `$name` and the right-hand side of `set`, and on its own for the
 * value of a command-line -D NAME=VALUE.
 *
 * Grammar, from the loosest to the tightest binding:
 *   sum      = product { ('+' | '-') product }          left associative
 *   product  = unary { ('*' | '/') unary }              left associative
 *   unary    = ('-' | '+') unary | power
 *   power    = primary [ '^' unary ]                    right associative: 2^3^2 = 512;
 *                                                       binds tighter than unary minus:
 *                                                       -2^2 = -4, and 2^-1 = 0.5
 *   primary  = number | '$' name | 'pi' | function '(' sum { ',' sum } ')' | '(' sum ')'
 * Numbers: 1  2.5  .5  3.  1e-3  2.5E+4 (a leading sign is the unary operator; there is
 * no hex, nan or inf). Functions: sin cos tan (radians), sqrt, abs (one argument);
 * min, max (two arguments). Names: letters, digits and '_', not starting with a digit.
 * Spaces, tabs and carriage returns between tokens are ignored. Parentheses nest at
 * most EXPRESSION_MAX_NESTING deep (so a hostile input cannot exhaust the stack).
 *
 * Errors: division by zero, unknown function or name, wrong argument count, unbalanced
 * parentheses, unexpected character, empty expression, undefined variable, sqrt of a
 * negative number, a number or intermediate result that is NaN or infinite. The message
 * says what was found and what was expected; it has NO position prefix: the evaluator
 * does not know the file or line, so it returns the column and the caller writes
 * "FILE:LINE:COLUMN: " (or "-D NAME=VALUE: column N: ") in front of the message.
 */
#ifndef RT_EXPRESSION_H
#define RT_EXPRESSION_H

#include <stdbool.h>
#include <stddef.h>

#include "status.h"

#define EXPRESSION_MAX_NESTING 256

/* Looks up the variable written $name (name is name_length bytes, not NUL-terminated,
 * without the '$'). Returns true and sets *value when the variable is defined, false
 * when it is not (the evaluator then reports "undefined variable $name"). */
typedef bool (*expression_variable_lookup)(void *context, const char *name, size_t name_length,
                                           double *value);

/* Evaluates the length bytes at text (need not be NUL-terminated) and stores the result,
 * always finite, in *value. base_column is the column of text[0] in the caller's
 * numbering. lookup (with lookup_context) resolves $variables; NULL means no variable
 * may be used here. Returns RT_OK, or RT_ERROR_INPUT with *error_column set to the column
 * of the offending character and error holding the unprefixed message. Allocates nothing
 * that outlives the call. error and error_column may be NULL. */
rt_status expression_evaluate(const char *text, size_t length, int base_column,
                              expression_variable_lookup lookup, void *lookup_context,
                              double *value, int *error_column, rt_error *error);

/* Returns true when the length bytes at name form a valid variable name: letters, digits
 * and '_', at least one byte, not starting with a digit. */
bool expression_is_variable_name(const char *name, size_t length);

#endif
