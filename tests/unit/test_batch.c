/* test_batch.c: frame lists, shard splits and output-name patterns (batch.h). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "batch.h"

static void frame_lists(void **state)
{
    (void)state;
    frame_list list;
    assert_int_equal(frame_list_parse("1-10,15,20-30:2", &list, NULL), RT_OK);
    int expected[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 15, 20, 22, 24, 26, 28, 30};
    assert_int_equal(list.count, 17);
    assert_memory_equal(list.frames, expected, sizeof expected);
    frame_list_free(&list);
    assert_int_equal(frame_list_parse("7", &list, NULL), RT_OK);
    assert_int_equal(list.count, 1);
    assert_int_equal(list.frames[0], 7);
    frame_list_free(&list);
    /* A step that does not land on the end stops before it (no chunk-size assumption). */
    assert_int_equal(frame_list_parse("1-10:4", &list, NULL), RT_OK);
    int stepped[] = {1, 5, 9};
    assert_int_equal(list.count, 3);
    assert_memory_equal(list.frames, stepped, sizeof stepped);
    frame_list_free(&list);
    /* Order is kept as given. */
    assert_int_equal(frame_list_parse("5,1,3", &list, NULL), RT_OK);
    assert_int_equal(list.frames[0], 5);
    assert_int_equal(list.frames[2], 3);
    frame_list_free(&list);
}

static void frame_list_errors(void **state)
{
    (void)state;
    const char *bad[][2] = {
        {"", "empty"},        {"5-2", "backwards"}, {"1-", "last frame"},      {"1-5:0", "step"},
        {"a", "frame number"}, {"1;2", "unexpected"}, {"1,1", "listed twice"}, {"1-3,2", "listed twice"},
        {"-3", "frame number"}, {"1-999999999", "frame number"}, {"1,", "frame number"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        frame_list list;
        rt_error error = {{0}};
        assert_int_equal(frame_list_parse(bad[i][0], &list, &error), RT_ERROR_INPUT);
        if (strstr(error.message, bad[i][1]) == NULL && strstr(error.message, "goes past") == NULL)
            fail_msg("'%s': message '%s' lacks '%s'", bad[i][0], error.message, bad[i][1]);
        assert_null(list.frames);
    }
}

static void shards(void **state)
{
    (void)state;
    int index, count;
    assert_int_equal(shard_parse("3/8", &index, &count, NULL), RT_OK);
    assert_int_equal(index, 3);
    assert_int_equal(count, 8);
    rt_error error;
    assert_int_equal(shard_parse("8/8", &index, &count, &error), RT_ERROR_INPUT);
    assert_int_equal(shard_parse("1/0", &index, &count, &error), RT_ERROR_INPUT);
    assert_int_equal(shard_parse("1-8", &index, &count, &error), RT_ERROR_INPUT);
    assert_int_equal(shard_parse("1/8x", &index, &count, &error), RT_ERROR_INPUT);
    /* Parts cover 0..total exactly once, contiguous, sizes differing by at most one. */
    for (long long total = 0; total < 40; total++)
        for (int parts = 1; parts < 12; parts++) {
            long long next = 0, smallest = total, largest = 0;
            for (int i = 0; i < parts; i++) {
                long long start, length;
                shard_range(i, parts, total, &start, &length);
                assert_int_equal(start, next);
                next = start + length;
                smallest = length < smallest ? length : smallest;
                largest = length > largest ? length : largest;
            }
            assert_int_equal(next, total);
            assert_true(largest - smallest <= 1);
        }
}

static void output_patterns(void **state)
{
    (void)state;
    char name[64];
    assert_true(output_pattern_has_frame("frame-%04d.png"));
    assert_false(output_pattern_has_frame("frame.png"));
    assert_int_equal(output_pattern_format("frame-%04d.png", 7, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "frame-0007.png");
    assert_int_equal(output_pattern_format("f%d.exr", 123, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "f123.exr");
    assert_int_equal(output_pattern_format("100%%-%3d.png", 5, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "100%-  5.png");
    rt_error error;
    assert_int_equal(output_pattern_format("a%d-%d.png", 1, name, sizeof name, &error), RT_ERROR_INPUT);
    assert_int_equal(output_pattern_format("a%s.png", 1, name, sizeof name, &error), RT_ERROR_INPUT);
    assert_int_equal(output_pattern_format("a%d.png", 1, name, 4, &error), RT_ERROR_INPUT);
}

/* Without --frames the output name is still a pattern: formatted with -D frame=VALUE, or 0. */
static void output_names_without_frames(void **state)
{
    (void)state;
    char name[64];
    assert_int_equal(output_name_without_frames("c-%d.exr", NULL, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "c-0.exr");
    assert_int_equal(output_name_without_frames("f-%04d.png", "12", name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "f-0012.png");
    assert_int_equal(output_name_without_frames("f-%d.png", "2*3+1", name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "f-7.png");
    assert_int_equal(output_name_without_frames("100%%.png", NULL, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "100%.png");
    /* Without a conversion the value of $frame does not matter, even when it is no frame. */
    assert_int_equal(output_name_without_frames("plain.png", "2.5", name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, "plain.png");
    const char *bad[][3] = {
        {"f-%d.png", "2.5", "not a frame number"},    {"f-%d.png", "-1", "not a frame number"},
        {"f-%d.png", "100000000", "not a frame number"}, {"f-%d.png", "1/0", "-D frame=1/0"},
        {"f-%d.png", "$x", "-D frame=$x"},           {"a%d-%d.png", NULL, "exactly one"},
        {"a%s.png", "1", "exactly one"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        rt_error error = {{0}};
        assert_int_equal(output_name_without_frames(bad[i][0], bad[i][1], name, sizeof name, &error), RT_ERROR_INPUT);
        if (strstr(error.message, bad[i][2]) == NULL)
            fail_msg("'%s' with frame '%s': message '%s' lacks '%s'", bad[i][0], bad[i][1] ? bad[i][1] : "(none)",
                     error.message, bad[i][2]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frame_lists),
        cmocka_unit_test(frame_list_errors),
        cmocka_unit_test(shards),
        cmocka_unit_test(output_patterns),
        cmocka_unit_test(output_names_without_frames),
    };
    return cmocka_run_group_tests_name("batch", tests, NULL, NULL);
}
