/* test_scene_lexer.c: unit tests of the scene parser's lexer on its own (core/scene_lexer.c):
 * lines, tokens, positions and where errors go. The messages of whole scenes are tested
 * through scene_load_string in test_scene_parse.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "scene_lexer.h"

/* A lexer, its report and one file of text (the caller's string) named "t.txt", with its
 * first line cut. */
typedef struct fixture {
    rt_error error;
    scene_report report;
    scene_lexer lexer;
    source_file file;
    source_line line;
} fixture;

/* Opens text as the top file of a fresh lexer in *f and cuts its first line into f->line;
 * lexer_free(&f->lexer) ends it. */
static void open_text(fixture *f, const char *text)
{
    memset(f, 0, sizeof *f);
    f->report = (scene_report){.error = &f->error, .status = RT_OK};
    lexer_init(&f->lexer, &f->report, 16);
    assert_true(lexer_open_string(&f->lexer, text, "t.txt", &f->file));
    assert_true(source_file_next_line(&f->file, &f->line));
}

/* Counts the lines of text and checks the text of line number `which` (1-based). */
static int count_lines(const char *text, int which, const char *expected)
{
    fixture f;
    open_text(&f, text);
    source_line line = f.line;
    int count = 0;
    do {
        count++;
        assert_int_equal(line.number, count);
        if (count == which) {
            assert_int_equal(line.length, strlen(expected));
            assert_memory_equal(line.text, expected, line.length);
        }
    } while (source_file_next_line(&f.file, &line));
    lexer_free(&f.lexer);
    return count;
}

/* Every file has a line; a final newline is followed by an empty last line; a UTF-8 byte
 * order mark is not part of the first line. */
static void test_lines(void **state)
{
    (void)state;
    assert_int_equal(count_lines("", 1, ""), 1);
    assert_int_equal(count_lines("sphere", 1, "sphere"), 1);
    assert_int_equal(count_lines("a\nb\n", 2, "b"), 3);
    assert_int_equal(count_lines("a\nb\n", 3, ""), 3);
    assert_int_equal(count_lines("\xEF\xBB\xBF" "camera\r\n", 1, "camera\r"), 2);
}

/* Reads every token of text's first line (braces allowed) into kinds and the token texts
 * joined by '|' into words; returns how many, with TOKEN_END not counted. */
static int lex_all(const char *text, token_kind kinds[16], char words[256])
{
    fixture f;
    open_text(&f, text);
    source_line line = f.line;
    int count = 0;
    words[0] = '\0';
    for (;;) {
        token t;
        assert_true(lex_token(&line, &t, true));
        if (t.kind == TOKEN_END)
            break;
        kinds[count++] = t.kind;
        strncat(words, line.text + t.offset, t.length);
        strcat(words, "|");
    }
    lexer_free(&f.lexer);
    return count;
}

/* Words end at spaces, comments, strings and braces; a '(' word runs to its ')' across
 * spaces; strings keep their quotes and may hold '#'. */
static void test_tokens(void **state)
{
    (void)state;
    token_kind kinds[16];
    char words[256];
    assert_int_equal(lex_all("sphere 0 (1 + 2) \"a # b\"{ } # note", kinds, words), 6);
    assert_string_equal(words, "sphere|0|(1 + 2)|\"a # b\"|{|}|");
    assert_int_equal(kinds[0], TOKEN_WORD);
    assert_int_equal(kinds[2], TOKEN_WORD);
    assert_int_equal(kinds[3], TOKEN_STRING);
    assert_int_equal(kinds[4], TOKEN_OPEN_BRACE);
    assert_int_equal(kinds[5], TOKEN_CLOSE_BRACE);
    /* An unclosed '(' runs to the comment, without the spaces before it. */
    assert_int_equal(lex_all("x (1 + (2)   # c", kinds, words), 2);
    assert_string_equal(words, "x|(1 + (2)|");
    assert_int_equal(lex_all("\t  ", kinds, words), 0);
}

/* A missing token is reported just after the last token; peeking does not consume; an
 * error goes to the report of the line's file with its position. */
static void test_positions_and_errors(void **state)
{
    (void)state;
    fixture f;
    open_text(&f, "\nradius 2   # c\nbad }");
    source_line line = f.line;
    assert_true(source_file_next_line(&f.file, &line));
    token t;
    assert_true(next_token(&line, &t));
    assert_true(token_is(&line, &t, "radius"));
    assert_false(token_is(&line, &t, "radiu"));
    assert_true(peek_token(&line, &t));
    assert_true(is_last_word(&line, &t));
    source_position two = token_position(&line, &t);
    assert_string_equal(two.path, "t.txt");
    assert_int_equal(two.line, 2);
    assert_int_equal(two.column, 8);
    assert_true(next_token(&line, &t));
    assert_true(next_token(&line, &t));
    assert_int_equal(t.kind, TOKEN_END);
    assert_int_equal(t.offset, 8);
    assert_true(expect_end_of_line(&line, "the radius"));
    assert_int_equal(f.report.status, RT_OK);

    assert_true(source_file_next_line(&f.file, &line));
    assert_true(next_token(&line, &t));
    assert_false(expect_end_of_line(&line, "the word"));
    assert_int_equal(f.report.status, RT_ERROR_INPUT);
    assert_string_equal(f.error.message,
                        "t.txt:3:5: unexpected '}' (a '}' closes a block on a line of its own)");
    assert_false(source_file_next_line(&f.file, &line));
    lexer_free(&f.lexer);
}

/* A statement's line must be text: a control byte is reported at its column. */
static void test_statement_bytes(void **state)
{
    (void)state;
    fixture f;
    open_text(&f, "camera \x01");
    token keyword;
    assert_false(lexer_start_statement(&f.line, &keyword));
    assert_string_equal(f.error.message,
                        "t.txt:1:8: unexpected byte 0x01 (a control character; scene files are text)");
    lexer_free(&f.lexer);
}

/* Relative paths resolve against the directory of the file that names them. */
static void test_relative_paths(void **state)
{
    (void)state;
    char *path = resolve_relative_path("scenes/a/main.txt", "../b.txt", 8);
    assert_string_equal(path, "scenes/a/../b.txt");
    free(path);
    path = resolve_relative_path("main.txt", "b.txt", 5);
    assert_string_equal(path, "b.txt");
    free(path);
    path = resolve_relative_path("scenes/main.txt", "/abs/b.txt", 10);
    assert_string_equal(path, "/abs/b.txt");
    free(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lines),
        cmocka_unit_test(test_tokens),
        cmocka_unit_test(test_positions_and_errors),
        cmocka_unit_test(test_statement_bytes),
        cmocka_unit_test(test_relative_paths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
