/* test_expression.c: unit tests of the expression evaluator (core/expression.c). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expression.h"
#include "support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Variables the tests can use: $a = 2, $b = 3, $abc = 10, $huge = 1e308. */
static bool test_lookup(void *context, const char *name, size_t length, double *value)
{
    int *calls = context;
    if (calls != NULL)
        (*calls)++;
    static const struct { const char *name; double value; } table[] = {
        {"a", 2}, {"b", 3}, {"abc", 10}, {"huge", 1e308},
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strlen(table[i].name) == length && memcmp(table[i].name, name, length) == 0) {
            *value = table[i].value;
            return true;
        }
    return false;
}

/* Evaluates text (with the test variables), failing the test unless it succeeds. */
static double evaluate_ok(const char *text)
{
    double value = -12345;
    int column = -1;
    rt_error error = {{0}};
    rt_status status = expression_evaluate(text, strlen(text), 1, test_lookup, NULL, &value, &column, &error);
    if (status != RT_OK)
        fail_msg("'%s' failed: column %d: %s", text, column, error.message);
    return value;
}

/* Evaluates text at base column base_column and checks that it fails at column with a
 * message containing phrase. */
static void check_failure_at(const char *text, int base_column, int column, const char *phrase)
{
    double value = -12345;
    int error_column = -1;
    rt_error error = {{0}};
    rt_status status = expression_evaluate(text, strlen(text), base_column, test_lookup, NULL, &value,
                                           &error_column, &error);
    if (status != RT_ERROR_INPUT)
        fail_msg("'%s' should fail with '%s' but gave status %d, value %g", text, phrase, status, value);
    if (error_column != column || strstr(error.message, phrase) == NULL)
        fail_msg("'%s': expected column %d and '%s', got column %d: %s", text, column, phrase, error_column,
                 error.message);
    assert_double_equal(value, -12345, 0);   /* the output is untouched on failure */
}

/* check_failure_at with the text starting at column 1. */
static void check_failure(const char *text, int column, const char *phrase)
{
    check_failure_at(text, 1, column, phrase);
}

static void test_literals(void **state)
{
    (void)state;
    assert_double_equal(evaluate_ok("1"), 1, 0);
    assert_double_equal(evaluate_ok("2.5"), 2.5, 0);
    assert_double_equal(evaluate_ok(".5"), 0.5, 0);
    assert_double_equal(evaluate_ok("3."), 3, 0);
    assert_double_equal(evaluate_ok("1e-3"), 1e-3, 0);
    assert_double_equal(evaluate_ok("2.5E+4"), 25000, 0);
    assert_double_equal(evaluate_ok("  7  "), 7, 0);
    assert_double_equal(evaluate_ok("\t7\r"), 7, 0);
    assert_double_equal(evaluate_ok("0.1"), 0.1, 0);
}

static void test_precedence(void **state)
{
    (void)state;
    assert_double_equal(evaluate_ok("1+2*3"), 7, 0);
    assert_double_equal(evaluate_ok("(1+2)*3"), 9, 0);
    assert_double_equal(evaluate_ok("2*3^2"), 18, 0);
    assert_double_equal(evaluate_ok("1 + 6 / 3"), 3, 0);
    assert_double_equal(evaluate_ok("-2^2"), -4, 0);          /* ^ binds tighter than unary minus */
    assert_double_equal(evaluate_ok("(-2)^2"), 4, 0);
    assert_double_equal(evaluate_ok("2^-1"), 0.5, 0);
    assert_double_equal(evaluate_ok("-3*2"), -6, 0);
    assert_double_equal(evaluate_ok("2*-3"), -6, 0);
    assert_double_equal(evaluate_ok("1 - -1"), 2, 0);
    assert_double_equal(evaluate_ok("--2"), 2, 0);
    assert_double_equal(evaluate_ok("-+-2"), 2, 0);
    assert_double_equal(evaluate_ok("+3"), 3, 0);
}

static void test_associativity(void **state)
{
    (void)state;
    assert_double_equal(evaluate_ok("10-4-3"), 3, 0);         /* left: (10-4)-3 */
    assert_double_equal(evaluate_ok("64/4/2"), 8, 0);         /* left: (64/4)/2 */
    assert_double_equal(evaluate_ok("2^3^2"), 512, 0);        /* right: 2^(3^2) */
    assert_double_equal(evaluate_ok("(2^3)^2"), 64, 0);
    assert_double_equal(evaluate_ok("2^-1^2"), 0.5, 0);       /* 2^(-(1^2)) */
}

static void test_functions_and_pi(void **state)
{
    (void)state;
    assert_double_equal(evaluate_ok("pi"), M_PI, 0);
    assert_double_equal(evaluate_ok("sin(pi/2)"), 1, 1e-15);
    assert_double_equal(evaluate_ok("cos(0)"), 1, 0);
    assert_double_equal(evaluate_ok("cos(pi)"), -1, 1e-15);
    assert_double_equal(evaluate_ok("tan(pi/4)"), 1, 1e-15);
    assert_double_equal(evaluate_ok("sqrt(16)"), 4, 0);
    assert_double_equal(evaluate_ok("sqrt(0)"), 0, 0);
    assert_double_equal(evaluate_ok("abs(-3)"), 3, 0);
    assert_double_equal(evaluate_ok("min(2, 3)"), 2, 0);
    assert_double_equal(evaluate_ok("max(2,3)"), 3, 0);
    assert_double_equal(evaluate_ok("max(min(1, 2), sqrt(abs(-9)))"), 3, 0);
    assert_double_equal(evaluate_ok("sin (0) + 1"), 1, 0);
    assert_double_equal(evaluate_ok("2*pi*0.5"), M_PI, 1e-15);
    assert_double_equal(evaluate_ok("-sqrt(4)^2"), -4, 0);    /* -(sqrt(4)^2) */
}

static void test_variables(void **state)
{
    (void)state;
    int calls = 0;
    double value = 0;
    const char *text = "$a*$b + $abc";
    assert_int_equal(expression_evaluate(text, strlen(text), 1, test_lookup, &calls, &value, NULL, NULL), RT_OK);
    assert_double_equal(value, 16, 0);
    assert_int_equal(calls, 3);
    assert_double_equal(evaluate_ok("4*cos($a - 2)"), 4, 0);
    assert_double_equal(evaluate_ok("-$a^2"), -4, 0);
}

static void test_length_limits_the_text(void **state)
{
    (void)state;
    /* Only the first length bytes are read: the rest of a scene line is not expression. */
    double value = 0;
    assert_int_equal(expression_evaluate("1+2 garbage", 3, 1, NULL, NULL, &value, NULL, NULL), RT_OK);
    assert_double_equal(value, 3, 0);
    assert_int_equal(expression_evaluate("$abcdef", 4, 1, test_lookup, NULL, &value, NULL, NULL), RT_OK);
    assert_double_equal(value, 10, 0);
}

static void test_error_columns_use_the_base_column(void **state)
{
    (void)state;
    check_failure_at("1/0", 1, 2, "division by zero");
    check_failure_at("1/0", 20, 21, "division by zero");
    check_failure_at("", 7, 7, "empty expression");
}

static void test_division_by_zero(void **state)
{
    (void)state;
    check_failure("1/0", 2, "division by zero");
    check_failure("1 / (2 - 2)", 3, "division by zero");
    check_failure("1/-0", 2, "division by zero");
}

static void test_unknown_function_and_name(void **state)
{
    (void)state;
    check_failure("foo(1)", 1, "unknown function 'foo'");
    check_failure("2 * log(1)", 5, "unknown function 'log'");
    check_failure("abc", 1, "unknown name 'abc'");
    check_failure("nan", 1, "unknown name 'nan'");
    check_failure("inf", 1, "unknown name 'inf'");
    check_failure("1 + sin", 5, "needs its arguments in parentheses");
    check_failure("pi(2)", 1, "'pi' is a constant");
}

static void test_wrong_argument_count(void **state)
{
    (void)state;
    check_failure("min(1)", 1, "min takes 2 arguments, found 1");
    check_failure("1+max(1,2,3)", 3, "max takes 2 arguments, found 3");
    check_failure("sin(1, 2)", 1, "sin takes 1 argument, found 2");
    check_failure("sqrt()", 1, "sqrt takes 1 argument, found 0");
}

static void test_unbalanced_parentheses(void **state)
{
    (void)state;
    check_failure("(1+2", 1, "unbalanced parentheses: this '(' is never closed");
    check_failure("2*((1+2)", 3, "never closed");
    check_failure("1+2)", 4, "unbalanced parentheses: ')' has no matching '('");
    check_failure("max(1,2", 4, "never closed");
    check_failure("(1,2)", 3, "unexpected ','");
}

static void test_unexpected_character(void **state)
{
    (void)state;
    check_failure("1 @ 2", 3, "unexpected character '@'");
    check_failure("@", 1, "unexpected character '@'");
    check_failure("1 2", 3, "unexpected character '2' (expected an operator");
    check_failure("1,2", 2, "unexpected ','");
    check_failure("*2", 1, "unexpected character '*'");
    check_failure("2 {", 3, "unexpected character '{'");
    check_failure("1\x01", 2, "unexpected character byte 0x01");
    check_failure("1+", 3, "expected a number, $variable, function or '(', found end of expression");
    check_failure("1+)", 3, "found ')'");
}

static void test_malformed_numbers(void **state)
{
    (void)state;
    check_failure("1.2.3", 1, "malformed number '1.2.3'");
    check_failure("2pi", 1, "malformed number '2pi'");
    check_failure("0x10", 1, "malformed number '0x10'");
    check_failure("1e", 1, "malformed number '1e'");
    check_failure("3 + .", 5, "malformed number '.'");
}

static void test_empty_expression(void **state)
{
    (void)state;
    check_failure("", 1, "empty expression");
    check_failure("   ", 1, "empty expression");
    check_failure("2*()", 3, "empty expression inside '( )'");
}

static void test_undefined_variable(void **state)
{
    (void)state;
    check_failure("1 + $nope", 5, "undefined variable $nope");
    check_failure("$", 1, "expected a variable name after '$'");
    check_failure("$1a", 1, "expected a variable name after '$'");

    double value = 0;
    int column = 0;
    rt_error error;
    assert_int_equal(expression_evaluate(" $a", 3, 5, NULL, NULL, &value, &column, &error), RT_ERROR_INPUT);
    assert_int_equal(column, 6);
    assert_non_null(strstr(error.message, "variables cannot be used here"));
}

static void test_sqrt_of_negative(void **state)
{
    (void)state;
    check_failure("sqrt(-1)", 1, "sqrt of a negative number (-1)");
    check_failure("2 + sqrt(1 - 3)", 5, "sqrt of a negative number (-2)");
}

static void test_non_finite_results(void **state)
{
    (void)state;
    check_failure("1e999", 1, "out of range");
    check_failure("1e308 * 10", 7, "the result of '*' is infinite");
    check_failure("$huge + $huge", 7, "the result of '+' is infinite");
    check_failure("-$huge - $huge", 8, "the result of '-' is infinite");
    check_failure("1 / 1e-308 / 1e-10", 12, "the result of '/' is infinite");
    check_failure("0^-1", 2, "the result of '^' is infinite");
    check_failure("(-8)^0.5", 5, "the result of '^' is not a number (NaN)");
    check_failure("10^400", 3, "infinite");
}

static void test_deep_nesting_is_refused(void **state)
{
    (void)state;
    size_t depth = 100000;
    char *text = malloc(2 * depth + 2);
    assert_non_null(text);
    memset(text, '(', depth);
    text[depth] = '1';
    memset(text + depth + 1, ')', depth);
    text[2 * depth + 1] = '\0';
    double value = 0;
    int column = 0;
    rt_error error;
    assert_int_equal(expression_evaluate(text, strlen(text), 1, NULL, NULL, &value, &column, &error),
                     RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "nested too deeply"));
    assert_int_equal(column, EXPRESSION_MAX_NESTING + 1);

    memset(text, '-', 2 * depth);
    text[2 * depth] = '1';
    assert_int_equal(expression_evaluate(text, strlen(text), 1, NULL, NULL, &value, &column, &error),
                     RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "nested too deeply"));
    free(text);

    /* Nesting within the limit works. */
    char nested[2 * 200 + 2];
    memset(nested, '(', 200);
    nested[200] = '5';
    memset(nested + 201, ')', 200);
    nested[401] = '\0';
    assert_double_equal(evaluate_ok(nested), 5, 0);
}

static void test_long_expression(void **state)
{
    (void)state;
    /* A flat sum is a loop, not recursion: any length works. */
    size_t terms = 200000;
    char *text = malloc(2 * terms + 1);
    assert_non_null(text);
    for (size_t i = 0; i < terms; i++) {
        text[2 * i] = '1';
        text[2 * i + 1] = '+';
    }
    text[2 * terms - 1] = '\0';
    assert_double_equal(evaluate_ok(text), (double)terms, 0);
    free(text);
}

static void test_error_may_be_null(void **state)
{
    (void)state;
    double value = 0;
    assert_int_equal(expression_evaluate("1/0", 3, 1, NULL, NULL, &value, NULL, NULL), RT_ERROR_INPUT);
}

static void test_variable_names(void **state)
{
    (void)state;
    assert_true(expression_is_variable_name("t", 1));
    assert_true(expression_is_variable_name("_x9", 3));
    assert_true(expression_is_variable_name("Light_X", 7));
    assert_false(expression_is_variable_name("", 0));
    assert_false(expression_is_variable_name("9x", 2));
    assert_false(expression_is_variable_name("a-b", 3));
    assert_false(expression_is_variable_name("$a", 2));
    assert_true(expression_is_variable_name("ab-", 2));     /* only length bytes count */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_literals),
        cmocka_unit_test(test_precedence),
        cmocka_unit_test(test_associativity),
        cmocka_unit_test(test_functions_and_pi),
        cmocka_unit_test(test_variables),
        cmocka_unit_test(test_length_limits_the_text),
        cmocka_unit_test(test_error_columns_use_the_base_column),
        cmocka_unit_test(test_division_by_zero),
        cmocka_unit_test(test_unknown_function_and_name),
        cmocka_unit_test(test_wrong_argument_count),
        cmocka_unit_test(test_unbalanced_parentheses),
        cmocka_unit_test(test_unexpected_character),
        cmocka_unit_test(test_malformed_numbers),
        cmocka_unit_test(test_empty_expression),
        cmocka_unit_test(test_undefined_variable),
        cmocka_unit_test(test_sqrt_of_negative),
        cmocka_unit_test(test_non_finite_results),
        cmocka_unit_test(test_deep_nesting_is_refused),
        cmocka_unit_test(test_long_expression),
        cmocka_unit_test(test_error_may_be_null),
        cmocka_unit_test(test_variable_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
