/* test_sweep.c: sweep tables (core/sweep.h): parsing, every refusal with its file:line,
 * and output names. */
#include "sweep.h"

#include "support.h"

/* A table with comments, blank lines, CRLF and spaces around fields. */
static void tables_parse(void **state)
{
    (void)state;
    sweep_table table;
    rt_error error = {{0}};
    const char *text = "# lights\r\n\n x , y_2 \r\n1, 2*pi\n# between\n-3 ,(4)\n";
    assert_int_equal(sweep_table_parse(text, "t.csv", ',', &table, &error), RT_OK);
    assert_int_equal(table.column_count, 2);
    assert_string_equal(table.names[0], "x");
    assert_string_equal(table.names[1], "y_2");
    assert_int_equal(table.header_line, 3);
    assert_int_equal(table.row_count, 2);
    assert_string_equal(table.values[0], "1");
    assert_string_equal(table.values[1], "2*pi");
    assert_string_equal(table.values[2], "-3");
    assert_string_equal(table.values[3], "(4)");
    assert_int_equal(table.lines[0], 4);
    assert_int_equal(table.lines[1], 6);
    char name[256];
    assert_int_equal(sweep_output_name("out-{x}-%03d.png", &table, 1, name, sizeof name, &error), RT_OK);
    assert_string_equal(name, "out--3-001.png");
    assert_int_equal(sweep_output_name("{y_2}.exr", &table, 0, name, sizeof name, &error), RT_OK);
    assert_string_equal(name, "2*pi.exr");
    assert_int_equal(sweep_output_name("{z}.exr", &table, 0, name, sizeof name, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "the output pattern's {z} is no column of t.csv");
    assert_int_equal(sweep_output_name("{x.exr", &table, 0, name, sizeof name, &error), RT_ERROR_INPUT);
    sweep_table_free(&table);
    /* A value's '%' is text, not a conversion. */
    assert_int_equal(sweep_table_parse("p\n50%\n", "t.tsv", '\t', &table, &error), RT_OK);
    assert_int_equal(sweep_output_name("a-{p}-%d.png", &table, 0, name, sizeof name, &error), RT_OK);
    assert_string_equal(name, "a-50%-0.png");
    sweep_table_free(&table);
}

/* Each refusal, with the table's name and line. */
static void bad_tables(void **state)
{
    (void)state;
    sweep_table table;
    rt_error error = {{0}};
    static const struct {
        const char *text, *message;
    } cases[] = {
        {"", "t.tsv: no header row of variable names"},
        {"# only a comment\n", "t.tsv: no header row of variable names"},
        {"a\tb\n", "t.tsv: a header but no row"},
        {"a\tb\n1\n", "t.tsv:2: 1 value, but the header (line 1) names 2 columns"},
        {"a\tb\n1\t2\t3\n", "t.tsv:2: 3 values, but the header (line 1) names 2 columns"},
        {"a\tb\n1\t \n", "t.tsv:2: no value for column 'b'"},
        {"a\ta\n1\t2\n", "t.tsv:1: column 'a' is named twice"},
        {"a\t2b\n1\t2\n", "t.tsv:1: column 2's name '2b' is not a scene variable name (letters, digits and '_')"},
        {"a\t$b\n1\t2\n", "t.tsv:1: column 2's name '$b' is not a scene variable name (letters, digits and '_')"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        assert_int_equal(sweep_table_parse(cases[i].text, "t.tsv", '\t', &table, &error), RT_ERROR_INPUT);
        assert_string_equal(error.message, cases[i].message);
        assert_null(table.values);
    }
    assert_int_equal(sweep_table_load("t.txt", &table, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "t.txt: a sweep table is a .tsv (tabs) or .csv (commas) file");
    assert_int_equal(sweep_table_load("/nonexistent/t.tsv", &table, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "/nonexistent/t.tsv: cannot read the sweep table");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tables_parse),
        cmocka_unit_test(bad_tables),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
