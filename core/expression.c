/* expression.c: see expression.h. A recursive descent parser that evaluates as it parses. */
#include "expression.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* How much of a bad token a message quotes; enough to recognise it, not a whole line. */
#define QUOTE_LIMIT 40

typedef struct evaluator {
    const char *text;
    size_t length;
    size_t position;
    int base_column;
    expression_variable_lookup lookup;
    void *lookup_context;
    int nesting;
    int *error_column;
    rt_error *error;
} evaluator;

typedef struct function_info {
    const char *name;
    int argument_count;
} function_info;

static const function_info functions[] = {
    {"sin", 1}, {"cos", 1}, {"tan", 1}, {"sqrt", 1}, {"abs", 1}, {"min", 2}, {"max", 2},
};
#define FUNCTION_COUNT ((int)(sizeof functions / sizeof functions[0]))

/* Character classes of names and numbers; explicit ranges, independent of the locale. */
static bool is_name_start(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

static bool is_name_char(int c)
{
    return is_name_start(c) || (c >= '0' && c <= '9');
}

static bool is_digit(int c)
{
    return c >= '0' && c <= '9';
}

bool expression_is_variable_name(const char *name, size_t length)
{
    if (length == 0 || !is_name_start((unsigned char)name[0]))
        return false;
    for (size_t i = 1; i < length; i++)
        if (!is_name_char((unsigned char)name[i]))
            return false;
    return true;
}

/* Records the column of text[offset] and the message; returns false so that a failing
 * parse step can end with `return fail(...)`. */
__attribute__((format(printf, 3, 4)))
static bool fail(evaluator *e, size_t offset, const char *format, ...)
{
    if (e->error_column != NULL) {
        long long column = (long long)e->base_column + (long long)offset;
        *e->error_column = column > INT_MAX ? INT_MAX : (int)column;
    }
    va_list arguments;
    va_start(arguments, format);
    rt_error_set_va(e->error, RT_ERROR_INPUT, format, arguments);
    va_end(arguments);
    return false;
}

/* Writes a short printable description of the character at offset into buffer:
 * 'x' for printable ASCII, "byte 0xNN" otherwise (a -D value may hold anything). */
static const char *describe_character(const evaluator *e, size_t offset, char *buffer, size_t size)
{
    if (offset >= e->length) {
        snprintf(buffer, size, "end of expression");
        return buffer;
    }
    unsigned char c = (unsigned char)e->text[offset];
    if (c >= 0x20 && c < 0x7f)
        snprintf(buffer, size, "'%c'", c);
    else
        snprintf(buffer, size, "byte 0x%02X", c);
    return buffer;
}

/* Formats value for a message: 15 significant digits show 0.1 as 0.1 and 1/3 as
 * 0.333333333333333. */
static void format_number(char *buffer, size_t size, double value)
{
    snprintf(buffer, size, "%.15g", value);
}

/* Returns the current byte, or -1 at the end of the text. */
static int peek(const evaluator *e)
{
    return e->position < e->length ? (unsigned char)e->text[e->position] : -1;
}

/* Skips the spaces, tabs and carriage returns allowed between tokens. */
static void skip_spaces(evaluator *e)
{
    while (e->position < e->length) {
        char c = e->text[e->position];
        if (c != ' ' && c != '\t' && c != '\r')
            break;
        e->position++;
    }
}

/* Checks that an intermediate result is a real, finite number; what names the operation
 * for the message ("'*'", "tan"). Reports at the operator or function name. */
static bool check_finite(evaluator *e, size_t offset, double value, const char *what)
{
    if (isnan(value))
        return fail(e, offset, "the result of %s is not a number (NaN)", what);
    if (isinf(value))
        return fail(e, offset, "the result of %s is infinite (too large)", what);
    return true;
}

/* Guards every recursion so that "((((...", "----..." or "2^2^2^..." of any length
 * fails cleanly instead of overflowing the stack. */
static bool enter_nesting(evaluator *e, size_t offset)
{
    if (++e->nesting > EXPRESSION_MAX_NESTING)
        return fail(e, offset, "expression nested too deeply (more than %d levels)",
                    EXPRESSION_MAX_NESTING);
    return true;
}

static bool parse_sum(evaluator *e, double *value);
static bool parse_unary(evaluator *e, double *value);

/* After an operand, the only things that may follow are an operator, a closing ')' or
 * ',' (when inside parentheses) or the end. Reports what else was found. */
static bool fail_after_operand(evaluator *e)
{
    char found[32];
    int c = peek(e);
    if (c == ')')
        return fail(e, e->position, "unbalanced parentheses: ')' has no matching '('");
    if (c == ',')
        return fail(e, e->position, "unexpected ',' (commas only separate function arguments)");
    return fail(e, e->position, "unexpected character %s (expected an operator: + - * / ^)",
                describe_character(e, e->position, found, sizeof found));
}

/* number: digits with an optional fraction and exponent. A run such as 1.2.3 or 2pi is
 * reported as one malformed number rather than as a confusing stray character. */
static bool parse_number(evaluator *e, double *value)
{
    size_t start = e->position;
    size_t digits = 0;
    while (is_digit(peek(e))) {
        e->position++;
        digits++;
    }
    if (peek(e) == '.') {
        e->position++;
        while (is_digit(peek(e))) {
            e->position++;
            digits++;
        }
    }
    if (digits > 0 && (peek(e) == 'e' || peek(e) == 'E')) {
        size_t exponent = e->position + 1;
        if (exponent < e->length && (e->text[exponent] == '+' || e->text[exponent] == '-'))
            exponent++;
        if (exponent < e->length && is_digit((unsigned char)e->text[exponent])) {
            e->position = exponent;
            while (is_digit(peek(e)))
                e->position++;
        }
    }
    if (digits == 0 || is_name_char(peek(e)) || peek(e) == '.') {
        while (is_name_char(peek(e)) || peek(e) == '.')
            e->position++;
        size_t length = e->position - start;
        return fail(e, start, "malformed number '%.*s%s'", (int)(length > QUOTE_LIMIT ? QUOTE_LIMIT : length),
                    e->text + start, length > QUOTE_LIMIT ? "..." : "");
    }

    /* strtod needs a terminated string; the scan above guarantees it accepts exactly
     * these bytes (so no hex, inf or nan can slip in). */
    size_t length = e->position - start;
    char small[64];
    char *copy = length < sizeof small ? small : malloc(length + 1);
    if (copy == NULL)
        return fail(e, start, "out of memory reading a number");
    memcpy(copy, e->text + start, length);
    copy[length] = '\0';
    *value = strtod(copy, NULL);
    if (copy != small)
        free(copy);
    if (!isfinite(*value))
        return fail(e, start, "number '%.*s%s' is out of range (too large for a double)",
                    (int)(length > QUOTE_LIMIT ? QUOTE_LIMIT : length), e->text + start,
                    length > QUOTE_LIMIT ? "..." : "");
    return true;
}

/* $name: asks the caller's lookup for the value. */
static bool parse_variable(evaluator *e, double *value)
{
    size_t dollar = e->position++;
    size_t name_start = e->position;
    while (is_name_char(peek(e)))
        e->position++;
    size_t name_length = e->position - name_start;
    if (!expression_is_variable_name(e->text + name_start, name_length))
        return fail(e, dollar, "expected a variable name after '$' (letters, digits and '_', "
                    "not starting with a digit)");
    const char *name = e->text + name_start;
    int shown = (int)(name_length > QUOTE_LIMIT ? QUOTE_LIMIT : name_length);
    if (e->lookup == NULL)
        return fail(e, dollar, "variables cannot be used here (found $%.*s)", shown, name);
    if (!e->lookup(e->lookup_context, name, name_length, value))
        return fail(e, dollar, "undefined variable $%.*s (a variable must be set before it is used)",
                    shown, name);
    return check_finite(e, dollar, *value, "the variable");
}

/* Computes functions[index] (arguments already counted and checked). */
static double apply_function(int index, const double *arguments)
{
    switch (index) {
    case 0: return sin(arguments[0]);
    case 1: return cos(arguments[0]);
    case 2: return tan(arguments[0]);
    case 3: return sqrt(arguments[0]);
    case 4: return fabs(arguments[0]);
    case 5: return fmin(arguments[0], arguments[1]);
    default: return fmax(arguments[0], arguments[1]);
    }
}

/* name: the constant pi, or a function call name(arguments). */
static bool parse_name(evaluator *e, double *value)
{
    size_t name_start = e->position;
    while (is_name_char(peek(e)))
        e->position++;
    size_t name_length = e->position - name_start;
    const char *name = e->text + name_start;
    int shown = (int)(name_length > QUOTE_LIMIT ? QUOTE_LIMIT : name_length);
    const char *ellipsis = name_length > QUOTE_LIMIT ? "..." : "";

    int function = -1;
    for (int i = 0; i < FUNCTION_COUNT; i++)
        if (strlen(functions[i].name) == name_length && memcmp(functions[i].name, name, name_length) == 0)
            function = i;
    bool is_pi = name_length == 2 && memcmp(name, "pi", 2) == 0;

    skip_spaces(e);
    if (peek(e) != '(') {
        if (is_pi) {
            *value = M_PI;
            return true;
        }
        if (function >= 0)
            return fail(e, name_start, "function '%s' needs its arguments in parentheses, e.g. %s(x)",
                        functions[function].name, functions[function].name);
        return fail(e, name_start, "unknown name '%.*s%s' (expected a number, $variable, pi or a "
                    "function; variables are written $name)", shown, name, ellipsis);
    }
    if (is_pi)
        return fail(e, name_start, "'pi' is a constant, not a function");
    if (function < 0)
        return fail(e, name_start, "unknown function '%.*s%s' (known: sin cos tan sqrt abs min max)",
                    shown, name, ellipsis);

    size_t open = e->position++;
    if (!enter_nesting(e, open))
        return false;
    double arguments[2] = {0, 0};
    int count = 0;
    skip_spaces(e);
    if (peek(e) == ')') {
        e->position++;
    } else {
        for (;;) {
            double argument;
            if (!parse_sum(e, &argument))
                return false;
            if (count < 2)
                arguments[count] = argument;
            count++;
            skip_spaces(e);
            int c = peek(e);
            if (c == -1)
                return fail(e, open, "unbalanced parentheses: this '(' is never closed");
            e->position++;
            if (c == ')')
                break;
            if (c != ',') {
                char found[32];
                return fail(e, e->position - 1, "expected ',' or ')' in the arguments of %s, found %s",
                            functions[function].name,
                            describe_character(e, e->position - 1, found, sizeof found));
            }
        }
    }
    e->nesting--;
    int expected = functions[function].argument_count;
    if (count != expected)
        return fail(e, name_start, "wrong number of arguments: %s takes %d argument%s, found %d",
                    functions[function].name, expected, expected == 1 ? "" : "s", count);
    if (function == 3 && arguments[0] < 0) {
        char number[40];
        format_number(number, sizeof number, arguments[0]);
        return fail(e, name_start, "sqrt of a negative number (%s)", number);
    }
    *value = apply_function(function, arguments);
    return check_finite(e, name_start, *value, functions[function].name);
}

/* primary: a number, $variable, pi, function call or parenthesised sum. */
static bool parse_primary(evaluator *e, double *value)
{
    skip_spaces(e);
    int c = peek(e);
    if (is_digit(c) || c == '.')
        return parse_number(e, value);
    if (c == '$')
        return parse_variable(e, value);
    if (is_name_start(c))
        return parse_name(e, value);
    if (c == '(') {
        size_t open = e->position++;
        if (!enter_nesting(e, open))
            return false;
        skip_spaces(e);
        if (peek(e) == ')')
            return fail(e, open, "empty expression inside '( )'");
        if (!parse_sum(e, value))
            return false;
        skip_spaces(e);
        if (peek(e) == -1)
            return fail(e, open, "unbalanced parentheses: this '(' is never closed");
        if (peek(e) != ')')
            return fail_after_operand(e);
        e->position++;
        e->nesting--;
        return true;
    }
    char found[32];
    if (c == -1 || c == ')' || c == ',')
        return fail(e, e->position, "expected a number, $variable, function or '(', found %s",
                    describe_character(e, e->position, found, sizeof found));
    return fail(e, e->position, "unexpected character %s (expected a number, $variable, function or '(')",
                describe_character(e, e->position, found, sizeof found));
}

/* power = primary [ '^' unary ]: the exponent is a unary so that 2^-1 works and the
 * recursion makes ^ right associative. */
static bool parse_power(evaluator *e, double *value)
{
    if (!parse_primary(e, value))
        return false;
    skip_spaces(e);
    if (peek(e) != '^')
        return true;
    size_t operator_position = e->position++;
    if (!enter_nesting(e, operator_position))
        return false;
    double exponent;
    if (!parse_unary(e, &exponent))
        return false;
    e->nesting--;
    *value = pow(*value, exponent);
    return check_finite(e, operator_position, *value, "'^'");
}

/* unary = ('-' | '+') unary | power: a sign applies to a whole power, so -2^2 = -4. */
static bool parse_unary(evaluator *e, double *value)
{
    skip_spaces(e);
    int c = peek(e);
    if (c != '-' && c != '+')
        return parse_power(e, value);
    if (!enter_nesting(e, e->position++))
        return false;
    if (!parse_unary(e, value))
        return false;
    e->nesting--;
    if (c == '-')
        *value = -*value;
    return true;
}

/* product = unary { ('*' | '/') unary }, left associative. */
static bool parse_product(evaluator *e, double *value)
{
    if (!parse_unary(e, value))
        return false;
    for (;;) {
        skip_spaces(e);
        int c = peek(e);
        if (c != '*' && c != '/')
            return true;
        size_t operator_position = e->position++;
        double right;
        if (!parse_unary(e, &right))
            return false;
        if (c == '/' && right == 0)
            return fail(e, operator_position, "division by zero");
        *value = c == '*' ? *value * right : *value / right;
        if (!check_finite(e, operator_position, *value, c == '*' ? "'*'" : "'/'"))
            return false;
    }
}

/* sum = product { ('+' | '-') product }, left associative; the whole grammar's root. */
static bool parse_sum(evaluator *e, double *value)
{
    if (!parse_product(e, value))
        return false;
    for (;;) {
        skip_spaces(e);
        int c = peek(e);
        if (c != '+' && c != '-')
            return true;
        size_t operator_position = e->position++;
        double right;
        if (!parse_product(e, &right))
            return false;
        *value = c == '+' ? *value + right : *value - right;
        if (!check_finite(e, operator_position, *value, c == '+' ? "'+'" : "'-'"))
            return false;
    }
}

rt_status expression_evaluate(const char *text, size_t length, int base_column,
                              expression_variable_lookup lookup, void *lookup_context,
                              double *value, int *error_column, rt_error *error)
{
    evaluator e = {
        .text = text, .length = length, .base_column = base_column,
        .lookup = lookup, .lookup_context = lookup_context,
        .error_column = error_column, .error = error,
    };
    double result = 0;
    skip_spaces(&e);
    if (e.position == e.length) {
        fail(&e, 0, "empty expression");
        return RT_ERROR_INPUT;
    }
    if (!parse_sum(&e, &result))
        return RT_ERROR_INPUT;
    skip_spaces(&e);
    if (e.position < e.length) {
        fail_after_operand(&e);
        return RT_ERROR_INPUT;
    }
    *value = result;
    return RT_OK;
}
